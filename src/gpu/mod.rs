//! GPU batch evaluation of quad quality (WGSL through wgpu) and its CPU twin.
