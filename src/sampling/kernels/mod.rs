//! The sampling kernels: the lane toolkit ([`lanes`]) and what is built from it, the B-spline
//! fast paths ([`shading`]), the dense ERBS kernel ([`dense`], with its explicit AVX path) and the
//! curvature-map updates ([`curvature`]). Kernels read tables and write grids; they know no
//! model and no sampler, and leave degenerate normals to the caller's model fallback.

pub(crate) mod curvature;
pub(crate) mod dense;
pub(crate) mod lanes;
pub(crate) mod shading;
#[cfg(test)]
pub(crate) mod testing;
