// steradian: the types a renderer uploads, as WGSL structs with the byte layout of the
// `#[repr(C)]` Rust types (`wgsl::TYPES`; the harness test `wgsl_layout` compares every
// offset and size). Vectors are `array<f32, 3>` (align 4, 12 bytes) rather than
// `vec3<f32>` (align 16), so an `array<CosineLobe>` in a storage buffer has the Rust
// slice's stride and `bytemuck::cast_slice(&[CosineLobe])` uploads it as it is.

// `lobe::CosineLobe`: s·max(a·v, 0)^e (20 bytes).
struct CosineLobe {
    axis: array<f32, 3>,
    scale: f32,
    exponent: f32,
}

// `lobe::cap::SphericalCap`: unit axis, half-angle α and 1 − cos α (20 bytes).
struct SphericalCap {
    axis: array<f32, 3>,
    half_angle: f32,
    one_minus_cos: f32,
}

// `rsl::Rsl`: centre, tangent, solid angle, light integral (RGB) and the radiance
// gradient of each channel (76 bytes).
struct Rsl {
    centre: array<f32, 3>,
    tangent: array<f32, 3>,
    solid_angle: f32,
    energy: array<f32, 3>,
    gradient: array<f32, 9>,
}

// `rsl::shade::ShadeLight`: an RSL prepared for shading; the per-light words of
// `wgsl::SHADE_MOMENTS`'s table, the first eight those of `wgsl::SHADE`'s (68 bytes).
struct ShadeLight {
    centre: array<f32, 3>,
    half_diagonal: f32,
    inv_solid_angle: f32,
    energy: array<f32, 3>,
    gradient: array<f32, 9>,
}
