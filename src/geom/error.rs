//! The one error type of the geometry layer.

/// Invalid geometric input. `field` names the offending input (`"knots"`, `"points"`, …) so that
/// callers such as the scene loader can say which object *and* field is wrong in one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("field '{field}': {message}")]
pub struct GeomError {
    /// Name of the input field the problem is in, as spelled in the scene format.
    pub field: &'static str,
    /// What is wrong, including indices and values where they help.
    pub message: String,
}

impl GeomError {
    pub fn new(field: &'static str, message: impl Into<String>) -> Self {
        Self {
            field,
            message: message.into(),
        }
    }
}

/// Shorthand for geometry results.
pub type GeomResult<T> = Result<T, GeomError>;
