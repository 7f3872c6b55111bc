//! The WGSL source, embedded in the binary, and its validation with naga (parse + validate,
//! errors rendered with spans) so a broken shader is a clear [`GpuError::Shader`] before any
//! device sees it.

use super::GpuError;

/// Path of the quality kernel in the repository (for messages).
pub const QUAD_QUALITY_PATH: &str = "shaders/quad_quality.wgsl";
/// Source of the quality kernel.
pub const QUAD_QUALITY: &str = include_str!("../../shaders/quad_quality.wgsl");
/// Entry point of the quality kernel (the CPU twin is `gpu::cpu::quad_quality`).
pub const ENTRY_POINT: &str = "quad_quality";
/// Entry point of the quality kernel on the precomputed-edges layout (CPU twin:
/// `gpu::cpu::quad_quality_local`).
pub const ENTRY_POINT_LOCAL: &str = "quad_quality_local";
/// Path of the streaming-copy kernel (bandwidth measurement).
pub const STREAM_COPY_PATH: &str = "shaders/stream_copy.wgsl";
/// Source of the streaming-copy kernel; entry point `stream_copy`.
pub const STREAM_COPY: &str = include_str!("../../shaders/stream_copy.wgsl");

/// Parses and validates WGSL `source` with naga; errors carry the rendered spans.
pub fn validate(source: &str, path: &str) -> Result<naga::Module, GpuError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| GpuError::Shader {
        path: path.to_string(),
        message: e.emit_to_string_with_path(source, path),
    })?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| GpuError::Shader {
        path: path.to_string(),
        message: e.emit_to_string_with_path(source, path),
    })?;
    Ok(module)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_kernel_is_valid_and_has_its_entry_point() {
        let module = validate(QUAD_QUALITY, QUAD_QUALITY_PATH).unwrap();
        assert!(module.entry_points.iter().any(|e| e.name == ENTRY_POINT));
        let module = validate(STREAM_COPY, STREAM_COPY_PATH).unwrap();
        assert!(module.entry_points.iter().any(|e| e.name == "stream_copy"));
    }

    #[test]
    fn broken_shader_is_a_clear_error_with_a_span() {
        let bad = QUAD_QUALITY.replace("let m = max(", "let m = maxx(");
        let err = validate(&bad, "broken.wgsl").unwrap_err().to_string();
        assert!(err.contains("broken.wgsl") && err.contains("maxx"), "{err}");
        let bad = "@compute @workgroup_size(1) fn f() { let x: u32 = 1.5; }";
        let err = validate(bad, "types.wgsl").unwrap_err().to_string();
        assert!(err.contains("types.wgsl"), "{err}");
    }
}
