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
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A poisoned lock only means a panic elsewhere while pushing; the list is still usable.
    fn lock(&self) -> MutexGuard<'_, Vec<ValidationMessage>> {
        self.messages.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Every message received so far.
    #[must_use]
    pub fn messages(&self) -> Vec<ValidationMessage> {
        self.lock().clone()
    }

    /// The error-severity messages received so far.
    #[must_use]
    pub fn errors(&self) -> Vec<ValidationMessage> {
        self.lock()
            .iter()
            .filter(|m| m.severity == Severity::Error)
            .cloned()
            .collect()
    }

    /// Removes and returns the error messages, keeping the others.
    #[must_use]
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

/// Messages that are not errors of this program and are dropped.
///
/// `VUID-VkSwapchainCreateInfoKHR-imageExtent-01274`: on X11 the window can be resized between
/// the surface-capabilities query and swapchain creation, so the extent we pass is checked
/// against a newer size; the race is inherent to X11 and harmless (the swapchain is rebuilt
/// when it reports out of date). wgpu-hal filters the same message.
const IGNORED: &[&str] = &["VUID-VkSwapchainCreateInfoKHR-imageExtent-01274"];

/// # Safety
/// Called by the Vulkan loader with `user_data` set by [`ValidationSink::messenger_info`].
///
/// Never unwinds into the driver: the body runs under `catch_unwind`, and it does nothing that
/// panics by design (stderr write errors are ignored, a poisoned lock is recovered).
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: forwarded from the loader under the same contract as this function's.
    let record = || unsafe { record_message(severity, data, user_data) };
    // AssertUnwindSafe: on a panic the only shared state, the sink, is behind a mutex whose
    // poisoning is tolerated, and the message is dropped.
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(record));
    // Returning FALSE is required: TRUE would make the layer abort the call.
    vk::FALSE
}

/// # Safety
/// `data` is null or valid for the call; `user_data` is null or points at the live sink of
/// [`ValidationSink::messenger_info`].
unsafe fn record_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) {
    // SAFETY: the loader passes a valid callback-data pointer (or null) for the call's duration.
    let Some(data) = (unsafe { data.as_ref() }) else {
        return;
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
    if IGNORED.contains(&message.id.as_str()) {
        return;
    }
    if message.severity >= Severity::Warning {
        use std::io::Write;
        // eprintln! panics when stderr is gone; a lost diagnostic is better than unwinding.
        let _ = writeln!(std::io::stderr(), "vulkan: {message}");
    }
    // SAFETY: user_data is `Arc::as_ptr` of a sink whose Arc the Instance keeps alive until
    // after vkDestroyInstance, the last call that can reach this callback.
    let Some(sink) = (unsafe { (user_data as *const Mutex<Vec<ValidationMessage>>).as_ref() })
    else {
        return;
    };
    sink.lock().unwrap_or_else(|p| p.into_inner()).push(message);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Calls the callback as the loader would, with a message id and text.
    fn deliver(
        sink: &ValidationSink,
        id: &std::ffi::CStr,
        severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    ) {
        let data = vk::DebugUtilsMessengerCallbackDataEXT::default()
            .message_id_name(id)
            .message(c"test message");
        let info = sink.messenger_info();
        // SAFETY: valid callback data for the call's duration; user data from the sink, which
        // outlives the call.
        let r = unsafe {
            debug_callback(
                severity,
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
                &data,
                info.p_user_data,
            )
        };
        assert_eq!(r, vk::FALSE);
    }

    #[test]
    fn callback_records_errors_and_drops_the_x11_extent_race() {
        let sink = ValidationSink::new();
        let error = vk::DebugUtilsMessageSeverityFlagsEXT::ERROR;
        deliver(&sink, c"VUID-vkCmdDraw-None-02859", error);
        deliver(
            &sink,
            c"VUID-VkSwapchainCreateInfoKHR-imageExtent-01274",
            error,
        );
        let errors = sink.errors();
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert_eq!(errors[0].id, "VUID-vkCmdDraw-None-02859");
        assert_eq!(errors[0].text, "test message");
    }

    #[test]
    fn callback_survives_null_pointers_and_a_poisoned_sink() {
        // SAFETY: null data and user data are handled without dereferencing.
        let r = unsafe {
            debug_callback(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                std::ptr::null(),
                std::ptr::null_mut(),
            )
        };
        assert_eq!(r, vk::FALSE);
        let sink = ValidationSink::new();
        let poisoner = sink.clone();
        let _ = std::thread::spawn(move || {
            let _guard = poisoner.messages.lock().unwrap();
            panic!("poison the sink");
        })
        .join();
        deliver(
            &sink,
            c"VUID-test",
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
        );
        assert_eq!(sink.errors().len(), 1);
    }
}
