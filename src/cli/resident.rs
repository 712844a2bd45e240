//! The process's resident memory, for `render --memory-report`: what the memory budget
//! estimates set against what the scene actually made resident.

use crate::sampling::budget::format_bytes;

/// Resident set size now and at its peak, in bytes (Linux `/proc/self/status`: `VmRSS`,
/// `VmHWM`); `None` where that file is not there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resident {
    pub now: u64,
    pub peak: u64,
}

impl Resident {
    /// The figures now.
    #[must_use]
    pub fn read() -> Option<Self> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        Some(Self {
            now: field(&status, "VmRSS:")?,
            peak: field(&status, "VmHWM:")?,
        })
    }
}

/// `NAME:   123 kB` as bytes.
fn field(status: &str, name: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with(name))?;
    let kb: u64 = line[name.len()..]
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse()
        .ok()?;
    kb.checked_mul(1024)
}

/// What a `render --memory-report` line says: the budget's estimate of the scene, and the
/// peak resident size less what the process held before loading it and what starting the
/// Vulkan driver added (neither is the scene's). The budget counts the scene only, not the
/// image: the image's own memory (`image`, from [`image_bytes`]) is named beside it, so that a
/// small scene rendered large does not read as a bad estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryReport {
    pub estimate: u64,
    pub image: u64,
    pub peak: u64,
    pub program: u64,
    pub driver: u64,
}

/// The memory a `width × height` image at `samples` samples takes besides the scene: the
/// multisampled colour and depth attachments (4 bytes a sample each), the resolved colour,
/// the read-back buffer and the pixels written out (4 bytes a pixel each).
#[must_use]
pub fn image_bytes(width: u32, height: u32, samples: u32) -> u64 {
    u64::from(width) * u64::from(height) * (8 * u64::from(samples.max(1)) + 12)
}

impl MemoryReport {
    /// The scene's measured bytes: the peak less the program and the driver.
    #[must_use]
    pub fn measured(&self) -> u64 {
        self.peak.saturating_sub(self.program + self.driver)
    }

    /// One line, with the ratio of the estimate to the measured bytes, the image's memory left
    /// out and put in.
    #[must_use]
    pub fn line(&self) -> String {
        let measured = self.measured();
        format!(
            "memory: estimate {} ({} B, the scene: what --memory-limit holds); measured {} ({measured} B: peak resident {} less {} before loading and {} for the Vulkan driver); estimate / measured {:.3}; with the image's attachments and read-back ({}, which the budget leaves out) {:.3}",
            format_bytes(self.estimate),
            self.estimate,
            format_bytes(measured),
            format_bytes(self.peak),
            format_bytes(self.program),
            format_bytes(self.driver),
            self.estimate as f64 / measured as f64,
            format_bytes(self.image),
            (self.estimate + self.image) as f64 / measured as f64
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_fields_parse_in_kilobytes() {
        let status = "Name:\tx\nVmHWM:\t  2048 kB\nVmRSS:\t  1024 kB\n";
        assert_eq!(field(status, "VmRSS:"), Some(1 << 20));
        assert_eq!(field(status, "VmHWM:"), Some(2 << 20));
        assert_eq!(field(status, "VmSwap:"), None);
        assert_eq!(field("VmRSS: lots kB", "VmRSS:"), None);
    }

    #[test]
    fn the_scene_is_the_peak_less_program_and_driver() {
        let r = MemoryReport {
            estimate: 900,
            image: 50,
            peak: 1500,
            program: 300,
            driver: 200,
        };
        assert_eq!(r.measured(), 1000);
        assert!(
            r.line().contains("estimate / measured 0.900;"),
            "{}",
            r.line()
        );
        assert!(r.line().ends_with("leaves out) 0.950"), "{}", r.line());
        assert_eq!(image_bytes(1280, 720, 4), 1280 * 720 * 44);
        assert_eq!(image_bytes(10, 10, 0), 100 * 20);
    }
}
