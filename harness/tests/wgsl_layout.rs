//! The types a renderer uploads have the same bytes on both sides: every struct of
//! `wgsl::TYPES` (parsed and validated by naga) has the size and field offsets of its
//! `#[repr(C)]` Rust twin (`LAYOUT`, from `size_of` and `offset_of!`), every struct has a
//! twin and every twin a struct, and `bytemuck::cast_slice` of a `&[CosineLobe]` puts each
//! field at the offset the WGSL struct reads.

use naga::valid::{Capabilities, ValidationFlags, Validator};
use steradian_core::Vec3;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::rsl::Rsl;
use steradian_core::rsl::shade::ShadeLight;
use steradian_core::wgsl::{self, Layout};

/// Every Rust type with a WGSL twin.
const LAYOUTS: [Layout; 4] = [
    CosineLobe::LAYOUT,
    SphericalCap::LAYOUT,
    Rsl::LAYOUT,
    ShadeLight::LAYOUT,
];

/// `(name, size, [(field, offset)])` of a WGSL struct.
type Struct = (String, usize, Vec<(String, usize)>);

/// Every struct of `wgsl::TYPES`, as naga lays it out.
fn wgsl_structs() -> Vec<Struct> {
    let module = naga::front::wgsl::parse_str(wgsl::TYPES)
        .unwrap_or_else(|e| panic!("TYPES: {}", e.emit_to_string(wgsl::TYPES)));
    Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("TYPES: {}", e.emit_to_string(wgsl::TYPES)));
    module
        .types
        .iter()
        .filter_map(|(_, t)| match &t.inner {
            naga::TypeInner::Struct { members, span } => Some((
                t.name.clone().unwrap_or_default(),
                *span as usize,
                members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
                    .collect(),
            )),
            _ => None,
        })
        .collect()
}

#[test]
fn wgsl_structs_have_the_rust_layouts() {
    let structs = wgsl_structs();
    assert_eq!(structs.len(), LAYOUTS.len(), "{structs:?}");
    for l in LAYOUTS {
        let (_, size, fields) = structs
            .iter()
            .find(|(n, _, _)| n == l.name)
            .unwrap_or_else(|| panic!("{} has no struct in wgsl::TYPES", l.name));
        assert_eq!(
            *size, l.size,
            "{}: WGSL size {size}, Rust {}",
            l.name, l.size
        );
        let rust: Vec<(String, usize)> =
            l.fields.iter().map(|(f, o)| (f.to_string(), *o)).collect();
        assert_eq!(fields, &rust, "{}: field offsets", l.name);
    }
}

/// The light words of the moments kernel's table are a `ShadeLight` (17 `f32`), and the
/// first eight those of the eq. 5 kernel's.
#[test]
fn shade_light_is_the_kernels_light_record() {
    use steradian_core::rsl::shade::gpu;
    assert_eq!(ShadeLight::LAYOUT.size, 4 * gpu::MOMENTS_LIGHT_WORDS);
    let energy = ShadeLight::LAYOUT.fields.iter().find(|f| f.0 == "energy");
    assert_eq!(energy.map(|f| f.1 + 12), Some(4 * gpu::SHADE_LIGHT_WORDS));
}

/// `bytemuck::cast_slice` uploads lobes with no copy: each field at its offset.
#[test]
fn cast_slice_puts_each_field_where_the_wgsl_struct_reads_it() {
    let lobes = [
        CosineLobe::new(Vec3::new(0.0, 0.6, 0.8), 2.5, 40.0).unwrap(),
        CosineLobe::new(Vec3::X, -0.5, 0.0).unwrap(),
    ];
    let words: &[f32] = bytemuck::cast_slice(&lobes);
    let stride = CosineLobe::LAYOUT.size / 4;
    assert_eq!(words.len(), 2 * stride);
    for (k, l) in lobes.iter().enumerate() {
        let w = &words[k * stride..(k + 1) * stride];
        assert_eq!(&w[..3], &l.axis().to_array());
        assert_eq!((w[3], w[4]), (l.scale(), l.exponent()));
    }
    let caps = [SphericalCap::new(Vec3::Z, 0.25).unwrap()];
    let w: &[f32] = bytemuck::cast_slice(&caps);
    assert_eq!((w[2], w[3]), (1.0, 0.25));
}
