//! WGSL sources of the GPU kernels, mirroring the scalar ones, as `pub const &str` so a
//! renderer can embed them. Each source is one compute entry point `main` with
//! `@workgroup_size(64)` reading storage buffers; see each constant for its bindings.
