//! Plain-old-data marker for values copied byte-wise into GPU memory or push constants.

/// Types whose every byte is initialised and whose bit patterns are all valid, so a `&[T]`
/// may be viewed as `&[u8]`.
///
/// # Safety
/// Implementors must be `#[repr(C)]` (or primitive) with no padding bytes.
pub(crate) unsafe trait Pod: Copy + 'static {}

// SAFETY: primitives and arrays of them have no padding.
unsafe impl Pod for f32 {}
// SAFETY: as above.
unsafe impl Pod for u32 {}
// SAFETY: as above.
unsafe impl<const N: usize> Pod for [f32; N] {}

/// Views a slice of `Pod` values as bytes.
pub(crate) fn slice_bytes<T: Pod>(v: &[T]) -> &[u8] {
    // SAFETY: `T: Pod` guarantees no padding/uninitialised bytes; the length covers exactly
    // the slice's memory and the lifetime is tied to `v`.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Views one `Pod` value as bytes.
pub(crate) fn bytes_of<T: Pod>(v: &T) -> &[u8] {
    slice_bytes(std::slice::from_ref(v))
}
