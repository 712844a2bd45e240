//! Vulkan entry, instance, optional validation layer and debug messenger.

use std::ffi::{CStr, c_char};
use std::sync::Once;

use ash::vk;
use raw_window_handle::RawDisplayHandle;

use super::error::{GpuError, GpuResult, VkResultExt};
use super::validation::ValidationSink;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Whether to load `VK_LAYER_KHRONOS_validation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ValidationMode {
    /// No layer, no messenger (release default).
    #[default]
    Off,
    /// Use the layer when installed, silently skip it otherwise.
    IfAvailable,
    /// Fail with [`GpuError::NoValidationLayer`] when it is not installed (tests).
    Required,
}

/// Parameters for [`Instance::new`].
#[derive(Clone, Debug, Default)]
pub struct InstanceDesc {
    /// Application name reported to the driver.
    pub app_name: String,
    /// Validation layer policy.
    pub validation: ValidationMode,
    /// Also turn on synchronization validation (slower; catches missing barriers).
    pub sync_validation: bool,
    /// Display the instance must be able to present to; `None` for headless use.
    pub display: Option<RawDisplayHandle>,
}

/// Owns the loader entry and the `VkInstance` (plus the debug messenger when validating).
pub struct Instance {
    pub(crate) entry: ash::Entry,
    pub(crate) raw: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Kept until after `vkDestroyInstance`: the messenger's user data points into it.
    sink: Option<ValidationSink>,
    pub(crate) surface_fn: Option<ash::khr::surface::Instance>,
}

/// Points the Vulkan loader at specific ICD manifest(s) (`VK_DRIVER_FILES`, plus the older
/// `VK_ICD_FILENAMES`) unless the user already set `VK_DRIVER_FILES`. Only the first call in a
/// process has an effect. To pick a device among installed drivers without touching the
/// environment, use [`super::RendererDesc::device`] instead.
///
/// # Safety
/// Mutates the process environment: no other thread may read or write the environment
/// while this runs (including C code such as a Vulkan loader in another thread), and it must
/// run before any Vulkan object of this process is created. Call it first thing in `main`,
/// before spawning threads.
pub unsafe fn force_driver_files(path: &str) {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if std::env::var_os("VK_DRIVER_FILES").is_some() {
            return;
        }
        // SAFETY: the caller guarantees no other thread touches the environment now;
        // concurrent callers of this function block on the Once until we return.
        unsafe {
            std::env::set_var("VK_DRIVER_FILES", path);
            std::env::set_var("VK_ICD_FILENAMES", path);
        }
    });
}

fn has_layer(entry: &ash::Entry, name: &CStr) -> GpuResult<bool> {
    // SAFETY: plain enumeration on a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .vk("vkEnumerateInstanceLayerProperties")?;
    Ok(layers
        .iter()
        .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == name)))
}

fn has_extension(entry: &ash::Entry, layer: Option<&CStr>, name: &CStr) -> GpuResult<bool> {
    // SAFETY: plain enumeration on a loaded entry; `layer` is a valid C string.
    let exts = unsafe { entry.enumerate_instance_extension_properties(layer) }
        .vk("vkEnumerateInstanceExtensionProperties")?;
    Ok(exts
        .iter()
        .any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name)))
}

impl Instance {
    /// Loads the Vulkan library and creates an instance (API 1.3).
    pub fn new(desc: &InstanceDesc) -> GpuResult<Self> {
        // SAFETY: loading the system Vulkan loader runs its initialisers; we trust libvulkan.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))?;

        // SAFETY: vkEnumerateInstanceVersion has no preconditions.
        let version = unsafe { entry.try_enumerate_instance_version() }
            .vk("vkEnumerateInstanceVersion")?
            .unwrap_or(vk::API_VERSION_1_0);
        if version < vk::API_VERSION_1_3 {
            return Err(GpuError::NoSuitableDevice(format!(
                "the Vulkan loader supports only {}.{}; Vulkan 1.3 is required",
                vk::api_version_major(version),
                vk::api_version_minor(version)
            )));
        }

        let validate = match desc.validation {
            ValidationMode::Off => false,
            ValidationMode::IfAvailable => has_layer(&entry, VALIDATION_LAYER)?,
            ValidationMode::Required => {
                if !has_layer(&entry, VALIDATION_LAYER)? {
                    return Err(GpuError::NoValidationLayer);
                }
                true
            }
        };
        let debug_utils = validate && has_extension(&entry, None, ash::ext::debug_utils::NAME)?;
        let sync_features = validate
            && desc.sync_validation
            && has_extension(
                &entry,
                Some(VALIDATION_LAYER),
                ash::ext::validation_features::NAME,
            )?;

        let mut extensions: Vec<*const c_char> = Vec::new();
        if let Some(display) = desc.display {
            let required = ash_window::enumerate_required_extensions(display)
                .map_err(|e| GpuError::Surface(format!("unsupported display: {e}")))?;
            extensions.extend_from_slice(required);
        }
        if debug_utils {
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        if sync_features {
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        let layers: Vec<*const c_char> = if validate {
            vec![VALIDATION_LAYER.as_ptr()]
        } else {
            Vec::new()
        };

        let app_name = std::ffi::CString::new(desc.app_name.replace('\0', ""))
            .unwrap_or_else(|_| c"prespline".to_owned());
        let app_info = vk::ApplicationInfo::default()
            .application_name(&app_name)
            .engine_name(c"prespline")
            .api_version(vk::API_VERSION_1_3);

        let sink = debug_utils.then(ValidationSink::new);
        // Chained into the create info so that vkCreateInstance/vkDestroyInstance are covered too.
        let mut messenger_info = sink.as_ref().map(ValidationSink::messenger_info);
        let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);

        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if let Some(m) = messenger_info.as_mut() {
            info = info.push_next(m);
        }
        if sync_features {
            info = info.push_next(&mut features);
        }

        // SAFETY: every pointer in `info` refers to locals that outlive this call.
        let raw = unsafe { entry.create_instance(&info, None) }.map_err(|e| match e {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => GpuError::NoDriver(String::new()),
            result => GpuError::Vk {
                call: "vkCreateInstance",
                result,
            },
        })?;

        let debug = match (&sink, messenger_info) {
            (Some(_), Some(m)) => {
                let loader = ash::ext::debug_utils::Instance::new(&entry, &raw);
                // SAFETY: valid instance; the sink behind user_data outlives the messenger.
                match unsafe { loader.create_debug_utils_messenger(&m, None) } {
                    Ok(messenger) => Some((loader, messenger)),
                    Err(result) => {
                        // SAFETY: nothing else was created from this instance yet.
                        unsafe { raw.destroy_instance(None) };
                        return Err(GpuError::Vk {
                            call: "vkCreateDebugUtilsMessengerEXT",
                            result,
                        });
                    }
                }
            }
            _ => None,
        };
        let surface_fn = desc
            .display
            .map(|_| ash::khr::surface::Instance::new(&entry, &raw));
        Ok(Self {
            entry,
            raw,
            debug,
            sink,
            surface_fn,
        })
    }

    /// The sink receiving validation messages, when validation is on.
    pub fn validation_sink(&self) -> Option<ValidationSink> {
        self.sink.clone()
    }

    /// Whether the validation layer is active.
    pub fn is_validating(&self) -> bool {
        self.debug.is_some()
    }

    /// Destroys the messenger and the instance.
    ///
    /// # Safety
    /// Every object created from the instance (device, surfaces) must already be destroyed.
    pub(crate) unsafe fn destroy(self) {
        if let Some((loader, messenger)) = self.debug {
            // SAFETY: the messenger belongs to this instance and is destroyed once.
            unsafe { loader.destroy_debug_utils_messenger(messenger, None) };
        }
        // SAFETY: the caller destroyed every child object (the device) before this.
        unsafe { self.raw.destroy_instance(None) };
        drop(self.sink);
    }
}
