//! Physical device choice, logical device, queue and the memory allocator.

use std::sync::{Mutex, MutexGuard};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::error::{GpuError, GpuResult, VkResultExt};
use super::instance::Instance;

/// Environment variable selecting a GPU by a substring of its name (case-insensitive).
pub const GPU_ENV: &str = "PRESPLINE_GPU";

/// What the renderer learned about the chosen device; fixed for the device's lifetime.
#[derive(Clone, Debug)]
pub struct DeviceCaps {
    /// Driver-reported device name, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub name: String,
    /// Discrete, integrated, virtual or CPU.
    pub device_type: vk::PhysicalDeviceType,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f64,
    /// Meaningful bits in a timestamp on our queue; 0 means timestamps are unsupported.
    pub timestamp_valid_bits: u32,
    /// Granularity of flushes of non-coherent host memory.
    pub non_coherent_atom_size: u64,
    /// Sample counts usable for both colour and depth attachments.
    pub sample_counts: vk::SampleCountFlags,
    /// Whether `fillModeNonSolid` was enabled (debug wireframe of arbitrary meshes).
    pub fill_mode_non_solid: bool,
    /// Whether `VK_EXT_multi_draw` is enabled: batches of surfaces cost one draw call.
    pub multi_draw: bool,
    /// Whether `largePoints` is enabled: control points are drawn as point primitives.
    pub large_points: bool,
}

impl DeviceCaps {
    /// Whether GPU timestamps can be taken on the graphics queue.
    #[must_use]
    pub fn timestamps(&self) -> bool {
        self.timestamp_valid_bits > 0
    }

    /// Whether `samples` (1, 2, 4, 8, ...) can be used for MSAA targets.
    #[must_use]
    pub fn supports_samples(&self, samples: u32) -> bool {
        samples.is_power_of_two()
            && self
                .sample_counts
                .contains(vk::SampleCountFlags::from_raw(samples))
    }

    /// The sample counts this device renders with, for messages: `1, 2 or 4`.
    #[must_use]
    pub fn sample_count_list(&self) -> String {
        let counts: Vec<String> = (0..7)
            .map(|k| 1u32 << k)
            .filter(|&n| self.supports_samples(n))
            .map(|n| n.to_string())
            .collect();
        match counts.as_slice() {
            [] => "1".into(),
            [one] => one.clone(),
            [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
        }
    }

    /// The MSAA sample count used when a target asks for 0, chosen per device type by
    /// measurement (docs/performance.md, "Frames"): 1 on CPU rasterisers (lavapipe), where 4×
    /// multisampling multiplies the cost of every triangle's rasterisation and of the resolve,
    /// and 4 on GPUs, where it is cheap. Falls back to 1 where 4 is not supported.
    #[must_use]
    pub fn default_samples(&self) -> u32 {
        let preferred = match self.device_type {
            vk::PhysicalDeviceType::CPU => 1,
            _ => 4,
        };
        if self.supports_samples(preferred) {
            preferred
        } else {
            1
        }
    }

    /// The sample count of a target asking for `requested` (0: [`Self::default_samples`]).
    pub(crate) fn resolve_samples(&self, requested: u32) -> GpuResult<vk::SampleCountFlags> {
        let n = if requested == 0 {
            self.default_samples()
        } else {
            requested
        };
        if !n.is_power_of_two() || !self.supports_samples(n) {
            return Err(GpuError::InvalidArgument(format!(
                "{n}x MSAA is not supported by {}, which renders with {} samples",
                self.name,
                self.sample_count_list()
            )));
        }
        Ok(vk::SampleCountFlags::from_raw(n))
    }
}

/// The logical device, its single graphics queue and the allocator.
pub struct Device {
    pub(crate) raw: ash::Device,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    pub(crate) caps: DeviceCaps,
    pub(crate) swapchain_fn: Option<ash::khr::swapchain::Device>,
    pub(crate) multi_draw: Option<MultiDraw>,
    /// `Option` so it can be dropped (freeing its memory blocks) before `vkDestroyDevice`.
    allocator: Mutex<Option<Allocator>>,
}

/// `VK_EXT_multi_draw`: many draws of one index buffer in one command.
pub(crate) struct MultiDraw {
    pub fns: ash::ext::multi_draw::Device,
    /// `maxMultiDrawCount`: draws per command at most (≥ 1).
    pub max_count: u32,
}

/// How desirable a device type is; higher wins.
pub(crate) fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 4,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 1,
        _ => 0,
    }
}

/// Picks among `(name, type)` candidates: the first whose name contains `preference`
/// (case-insensitive) when given, else the best-ranked type (first wins on ties).
pub(crate) fn choose(
    candidates: &[(String, vk::PhysicalDeviceType)],
    preference: Option<&str>,
) -> Result<usize, String> {
    if candidates.is_empty() {
        return Err(
            "no device supports Vulkan 1.3 with dynamic rendering, synchronization2 \
                    and buffer device addresses"
                .into(),
        );
    }
    if let Some(want) = preference.filter(|p| !p.is_empty()) {
        let want = want.to_lowercase();
        return candidates
            .iter()
            .position(|(name, _)| name.to_lowercase().contains(&want))
            .ok_or_else(|| {
                let names: Vec<&str> = candidates.iter().map(|(n, _)| n.as_str()).collect();
                format!("{GPU_ENV}={want:?} matches none of: {}", names.join(", "))
            });
    }
    let mut best = 0;
    for (i, (_, t)) in candidates.iter().enumerate() {
        if type_rank(*t) > type_rank(candidates[best].1) {
            best = i;
        }
    }
    Ok(best)
}

struct Candidate {
    physical: vk::PhysicalDevice,
    name: String,
    props: vk::PhysicalDeviceProperties,
    queue_family: u32,
    timestamp_valid_bits: u32,
    swapchain: bool,
    fill_mode_non_solid: bool,
    /// `largePoints`, and a point size range reaching 16 pixels.
    large_points: bool,
    /// `maxMultiDrawCount` when `VK_EXT_multi_draw` and its feature are available.
    multi_draw: Option<u32>,
}

fn inspect(
    instance: &Instance,
    physical: vk::PhysicalDevice,
    want_swapchain: bool,
) -> GpuResult<Option<Candidate>> {
    let raw = &instance.raw;
    // SAFETY: `physical` was enumerated from this instance.
    let props = unsafe { raw.get_physical_device_properties(physical) };
    if props.api_version < vk::API_VERSION_1_3 {
        return Ok(None);
    }
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f12)
        .push_next(&mut f13);
    // SAFETY: the chain only holds structs known to Vulkan 1.3, which the device supports.
    unsafe { raw.get_physical_device_features2(physical, &mut f2) };
    let fill_mode_non_solid = f2.features.fill_mode_non_solid == vk::TRUE;
    let large_points =
        f2.features.large_points == vk::TRUE && props.limits.point_size_range[1] >= 16.0;
    if f13.dynamic_rendering != vk::TRUE
        || f13.synchronization2 != vk::TRUE
        || f12.buffer_device_address != vk::TRUE
    {
        return Ok(None);
    }
    // SAFETY: as above.
    let families = unsafe { raw.get_physical_device_queue_family_properties(physical) };
    let Some((family, fam)) = families
        .iter()
        .enumerate()
        .find(|(_, f)| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
    else {
        return Ok(None);
    };
    // SAFETY: as above.
    let exts = unsafe { raw.enumerate_device_extension_properties(physical) }
        .vk("vkEnumerateDeviceExtensionProperties")?;
    let swapchain = exts.iter().any(|e| {
        e.extension_name_as_c_str()
            .is_ok_and(|n| n == ash::khr::swapchain::NAME)
    });
    if want_swapchain && !swapchain {
        return Ok(None);
    }
    let has_multi_draw = exts.iter().any(|e| {
        e.extension_name_as_c_str()
            .is_ok_and(|n| n == ash::ext::multi_draw::NAME)
    });
    let multi_draw = has_multi_draw
        .then(|| multi_draw_limit(instance, physical))
        .flatten();
    let name = props
        .device_name_as_c_str()
        .map(|c| c.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "unnamed device".into());
    Ok(Some(Candidate {
        physical,
        name,
        props,
        queue_family: family as u32,
        timestamp_valid_bits: fam.timestamp_valid_bits,
        swapchain: want_swapchain,
        fill_mode_non_solid,
        large_points,
        multi_draw,
    }))
}

/// `maxMultiDrawCount` when the device reports the `multiDraw` feature (it has the extension).
fn multi_draw_limit(instance: &Instance, physical: vk::PhysicalDevice) -> Option<u32> {
    let raw = &instance.raw;
    let mut features = vk::PhysicalDeviceMultiDrawFeaturesEXT::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut features);
    // SAFETY: the device supports VK_EXT_multi_draw, so its feature struct may be chained.
    unsafe { raw.get_physical_device_features2(physical, &mut f2) };
    if features.multi_draw != vk::TRUE {
        return None;
    }
    let mut props = vk::PhysicalDeviceMultiDrawPropertiesEXT::default();
    let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props);
    // SAFETY: as above, for the properties struct.
    unsafe { raw.get_physical_device_properties2(physical, &mut p2) };
    (props.max_multi_draw_count > 0).then_some(props.max_multi_draw_count)
}

impl Device {
    /// Chooses a physical device (`preference`: a name substring, else [`GPU_ENV`]) and creates
    /// the logical device. When the instance was created for a display, `VK_KHR_swapchain` is
    /// required and enabled.
    pub fn new(instance: &Instance, preference: Option<&str>) -> GpuResult<Self> {
        let want_swapchain = instance.surface_fn.is_some();
        // SAFETY: valid instance.
        let physicals = unsafe { instance.raw.enumerate_physical_devices() }
            .vk("vkEnumeratePhysicalDevices")?;
        if physicals.is_empty() {
            return Err(GpuError::NoDriver(" (no physical devices)".into()));
        }
        let mut candidates = Vec::new();
        for p in physicals {
            if let Some(c) = inspect(instance, p, want_swapchain)? {
                candidates.push(c);
            }
        }
        let preference = preference
            .map(str::to_owned)
            .or_else(|| std::env::var(GPU_ENV).ok());
        let listing: Vec<_> = candidates
            .iter()
            .map(|c| (c.name.clone(), c.props.device_type))
            .collect();
        let chosen = choose(&listing, preference.as_deref()).map_err(GpuError::NoSuitableDevice)?;
        let c = candidates.swap_remove(chosen);
        Self::create(instance, c)
    }

    fn create(instance: &Instance, c: Candidate) -> GpuResult<Self> {
        let raw_instance = &instance.raw;
        let priorities = [1.0];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(c.queue_family)
            .queue_priorities(&priorities)];
        let mut extensions = Vec::new();
        if c.swapchain {
            extensions.push(ash::khr::swapchain::NAME.as_ptr());
        }
        if c.multi_draw.is_some() {
            extensions.push(ash::ext::multi_draw::NAME.as_ptr());
        }
        let mut multi_draw_features =
            vk::PhysicalDeviceMultiDrawFeaturesEXT::default().multi_draw(true);
        let features = vk::PhysicalDeviceFeatures::default()
            .fill_mode_non_solid(c.fill_mode_non_solid)
            .large_points(c.large_points);
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default().buffer_device_address(true);
        // Demotion is how SPIR-V 1.6 spells `discard` (the HUD's glyph lookup); Vulkan 1.3
        // requires every device to support it.
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .shader_demote_to_helper_invocation(true);
        let mut info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&extensions)
            .enabled_features(&features)
            .push_next(&mut f12)
            .push_next(&mut f13);
        if c.multi_draw.is_some() {
            info = info.push_next(&mut multi_draw_features);
        }
        // SAFETY: features and extensions were checked in `inspect`; pointers outlive the call.
        let raw =
            unsafe { raw_instance.create_device(c.physical, &info, None) }.vk("vkCreateDevice")?;
        // SAFETY: the queue family/index pair was requested in `info`.
        let queue = unsafe { raw.get_device_queue(c.queue_family, 0) };

        let limits = &c.props.limits;
        let caps = DeviceCaps {
            name: c.name,
            device_type: c.props.device_type,
            timestamp_period_ns: f64::from(limits.timestamp_period),
            timestamp_valid_bits: if limits.timestamp_period > 0.0 {
                c.timestamp_valid_bits
            } else {
                0
            },
            non_coherent_atom_size: limits.non_coherent_atom_size.max(1),
            sample_counts: limits.framebuffer_color_sample_counts
                & limits.framebuffer_depth_sample_counts,
            fill_mode_non_solid: c.fill_mode_non_solid,
            multi_draw: c.multi_draw.is_some(),
            large_points: c.large_points,
        };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: raw_instance.clone(),
            device: raw.clone(),
            physical_device: c.physical,
            debug_settings: Default::default(),
            buffer_device_address: true,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: nothing was created from the device yet.
                unsafe { raw.destroy_device(None) };
                return Err(e.into());
            }
        };
        let swapchain_fn = c
            .swapchain
            .then(|| ash::khr::swapchain::Device::new(raw_instance, &raw));
        let multi_draw = c.multi_draw.map(|max_count| MultiDraw {
            fns: ash::ext::multi_draw::Device::new(raw_instance, &raw),
            max_count,
        });
        Ok(Self {
            raw,
            physical: c.physical,
            queue,
            queue_family: c.queue_family,
            caps,
            swapchain_fn,
            multi_draw,
            allocator: Mutex::new(Some(allocator)),
        })
    }

    /// Capabilities of the chosen device.
    pub fn caps(&self) -> &DeviceCaps {
        &self.caps
    }

    /// The raw `ash` device, for code that needs a call this module does not wrap.
    pub fn raw(&self) -> &ash::Device {
        &self.raw
    }

    /// Allocates memory for a resource through gpu-allocator (images are not linear, buffers
    /// are). Fails once teardown has taken the allocator.
    pub(crate) fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: gpu_allocator::MemoryLocation,
        linear: bool,
    ) -> GpuResult<gpu_allocator::vulkan::Allocation> {
        match self.allocator().as_mut() {
            Some(a) => a
                .allocate(&gpu_allocator::vulkan::AllocationCreateDesc {
                    name,
                    requirements,
                    location,
                    linear,
                    allocation_scheme: gpu_allocator::vulkan::AllocationScheme::GpuAllocatorManaged,
                })
                .map_err(GpuError::from),
            None => Err(GpuError::InvalidArgument(
                "device is being destroyed".into(),
            )),
        }
    }

    /// Locks the allocator. `None` only after [`Device::destroy`] started, which cannot be
    /// observed from safe code since `destroy` takes `self`.
    pub(crate) fn allocator(&self) -> MutexGuard<'_, Option<Allocator>> {
        // A poisoned lock only means a panic elsewhere; the allocator itself is consistent.
        self.allocator.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Blocks until the GPU is idle.
    pub fn wait_idle(&self) -> GpuResult<()> {
        // SAFETY: valid device; no external synchronisation needed beyond &self (single queue
        // owned by us, never submitted to concurrently since submission needs &mut Renderer).
        unsafe { self.raw.device_wait_idle() }.vk("vkDeviceWaitIdle")
    }

    /// Frees the allocator's memory blocks and destroys the device.
    ///
    /// # Safety
    /// Every object created from the device must already be destroyed and the GPU idle (or
    /// the device lost).
    pub(crate) unsafe fn destroy(self) {
        drop(
            self.allocator
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .take(),
        );
        // SAFETY: all children were destroyed by the caller and the GPU is idle.
        unsafe { self.raw.destroy_device(None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vk::PhysicalDeviceType as T;

    fn list() -> Vec<(String, vk::PhysicalDeviceType)> {
        vec![
            ("llvmpipe (LLVM 15)".into(), T::CPU),
            ("Intel(R) UHD 620".into(), T::INTEGRATED_GPU),
            ("NVIDIA GeForce RTX 4070".into(), T::DISCRETE_GPU),
            ("Virtio GPU".into(), T::VIRTUAL_GPU),
        ]
    }

    #[test]
    fn prefers_discrete_then_integrated_then_virtual_then_cpu() {
        let mut l = list();
        assert_eq!(choose(&l, None), Ok(2));
        l.remove(2);
        assert_eq!(choose(&l, None), Ok(1));
        l.remove(1);
        assert_eq!(choose(&l, None), Ok(1));
        l.remove(1);
        assert_eq!(choose(&l, None), Ok(0));
        assert!(choose(&[], None).is_err());
    }

    #[test]
    fn env_override_matches_name_substring() {
        let l = list();
        assert_eq!(choose(&l, Some("LLVMPIPE")), Ok(0));
        assert_eq!(choose(&l, Some("uhd")), Ok(1));
        assert_eq!(choose(&l, Some("")), Ok(2));
        let err = choose(&l, Some("radeon")).unwrap_err();
        assert!(
            err.contains("PRESPLINE_GPU") && err.contains("llvmpipe"),
            "{err}"
        );
    }
}
