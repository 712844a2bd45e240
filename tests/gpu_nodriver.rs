//! With no usable Vulkan driver, creating a renderer fails with one clear line saying what
//! to install. (Own test binary: the driver override is process-wide.)

use prespline::gpu::{GpuError, Renderer, RendererDesc, force_driver_files};

#[test]
fn missing_driver_is_one_clear_error() {
    let bogus = "/nonexistent/prespline-no-such-icd.json";
    force_driver_files(bogus);
    if std::env::var("VK_DRIVER_FILES").as_deref() != Ok(bogus) {
        eprintln!("skipped: VK_DRIVER_FILES is set by the environment");
        return;
    }
    let err = match Renderer::new(&RendererDesc::default()) {
        Ok(_) => panic!("a renderer was created without any driver"),
        Err(e) => e,
    };
    assert!(
        matches!(err, GpuError::NoDriver(_) | GpuError::NoLoader(_)),
        "unexpected error: {err:?}"
    );
    let text = err.to_string();
    eprintln!("error shown to users: {text}");
    assert!(!text.contains('\n'), "not one line: {text}");
    assert!(
        text.contains("mesa-vulkan-drivers") && text.contains("libvulkan1"),
        "no install hint: {text}"
    );
}
