//! A sink for `VK_EXT_debug_utils` messages, so tests can fail on any validation error.
//!
//! The sink is shared (`Arc`): the instance keeps one handle alive until after
//! `vkDestroyInstance` (so leak reports at teardown still land in it) and a test keeps another
//! to inspect after the renderer is gone.

use std::ffi::{CStr, c_void};
use std::fmt;
use std::sync::{Arc, Mutex, MutexGuard};

use ash::vk;

/// How bad a message is, mirroring `VkDebugUtilsMessageSeverityFlagBitsEXT`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Diagnostic chatter.
    Verbose,
    /// Informational.
    Info,
    /// Probably a mistake or a performance problem; not a spec violation.
    Warning,
    /// A violation of the Vulkan specification.
    Error,
}

/// One message received from the validation layer (or the loader).
#[derive(Clone, Debug)]
pub struct ValidationMessage {
    /// Severity reported by the layer.
    pub severity: Severity,
    /// The VUID or message id name, e.g. `VUID-vkDestroyDevice-device-05137`.
    pub id: String,
    /// The full message text.
    pub text: String,
}

impl fmt::Display for ValidationMessage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{:?}] {}: {}", self.severity, self.id, self.text)
    }
}

/// Collects validation messages. Cheap to clone; all clones share one list.
#[derive(Clone, Default)]
pub struct ValidationSink {
    messages: Arc<Mutex<Vec<ValidationMessage>>>,
}

impl fmt::Debug for ValidationSink {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ValidationSink")
            .field("messages", &self.lock().len())
            .finish()
    }
}

impl ValidationSink {
    /// An empty sink.
    pub fn new() -> Self {
        Self::default()
    }

    /// A poisoned lock only means a panic elsewhere while pushing; the list is still usable.
    fn lock(&self) -> MutexGuard<'_, Vec<ValidationMessage>> {
        self.messages.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Every message received so far.
    pub fn messages(&self) -> Vec<ValidationMessage> {
        self.lock().clone()
    }

    /// The error-severity messages received so far.
    pub fn errors(&self) -> Vec<ValidationMessage> {
        self.lock()
            .iter()
            .filter(|m| m.severity == Severity::Error)
            .cloned()
            .collect()
    }

    /// Removes and returns the error messages, keeping the others.
    pub fn take_errors(&self) -> Vec<ValidationMessage> {
        let mut all = self.lock();
        let (errors, rest) = all.drain(..).partition(|m| m.severity == Severity::Error);
        *all = rest;
        errors
    }

    /// Records a message; used by the debug callback (and by tests of the sink itself).
    pub fn push(&self, message: ValidationMessage) {
        self.lock().push(message);
    }

    /// Messenger create info whose callback appends to this sink. The returned struct borrows
    /// nothing, but its user-data pointer is only valid while some clone of `self` is alive.
    pub(crate) fn messenger_info(&self) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
        vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&self.messages) as *mut c_void)
    }
}

fn severity_of(flags: vk::DebugUtilsMessageSeverityFlagsEXT) -> Severity {
    if flags.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        Severity::Error
    } else if flags.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        Severity::Warning
    } else if flags.contains(vk::DebugUtilsMessageSeverityFlagsEXT::INFO) {
        Severity::Info
    } else {
        Severity::Verbose
    }
}

/// # Safety
/// Called by the Vulkan loader with `user_data` set by [`ValidationSink::messenger_info`].
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes a valid callback-data pointer (or null) for the call's duration.
    let Some(data) = (unsafe { data.as_ref() }) else {
        return vk::FALSE;
    };
    let text = |p: *const std::ffi::c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: non-null message strings from the layer are NUL-terminated.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    let message = ValidationMessage {
        severity: severity_of(severity),
        id: text(data.p_message_id_name),
        text: text(data.p_message),
    };
    if message.severity >= Severity::Warning {
        eprintln!("vulkan: {message}");
    }
    // SAFETY: user_data is `Arc::as_ptr` of a sink whose Arc the Instance keeps alive until
    // after vkDestroyInstance, the last call that can reach this callback.
    let sink = unsafe { &*(user_data as *const Mutex<Vec<ValidationMessage>>) };
    sink.lock().unwrap_or_else(|p| p.into_inner()).push(message);
    // Returning FALSE is required: TRUE would make the layer abort the call.
    vk::FALSE
}
