//! Every WGSL kernel (`wgsl::ALL` and `wgsl::CUSTOM`) parses and validates with naga (no
//! device needed), has the entry point `main` with `@workgroup_size(64)`, and the bindings
//! documented in `steradian_core::wgsl`.

use naga::valid::{Capabilities, ValidationFlags, Validator};
use naga::{AddressSpace, ShaderStage, StorageAccess};
use steradian_core::wgsl;
use steradian_harness::registry;

fn module(name: &str, src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}: WGSL parse error:\n{}", e.emit_to_string(src)));
    Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: WGSL validation error:\n{}", e.emit_to_string(src)));
    module
}

/// `(binding, name, space)` of the expected globals of a kernel.
fn expected(with_table: bool) -> Vec<(u32, &'static str, AddressSpace)> {
    let mut v = vec![
        (
            0,
            "input",
            AddressSpace::Storage {
                access: StorageAccess::LOAD,
            },
        ),
        (
            1,
            "output",
            AddressSpace::Storage {
                access: StorageAccess::LOAD | StorageAccess::STORE,
            },
        ),
        (2, "params", AddressSpace::Uniform),
    ];
    if with_table {
        v.push((
            3,
            "table",
            AddressSpace::Storage {
                access: StorageAccess::LOAD,
            },
        ));
    }
    v
}

/// Entry point `main` with 64 threads, and exactly the documented bindings in group 0; the
/// table (binding 3), where there is one, of `table_elem` (`"f32"` or `"u32"`).
fn check_interface(name: &str, src: &str, table_elem: Option<&str>) {
    let m = module(name, src);

    // One compute entry point `main`, 64 threads.
    assert_eq!(m.entry_points.len(), 1, "{name}: entry points");
    let ep = &m.entry_points[0];
    assert_eq!(ep.name, "main", "{name}: entry point name");
    assert_eq!(ep.stage, ShaderStage::Compute, "{name}: stage");
    assert_eq!(ep.workgroup_size, [64, 1, 1], "{name}: workgroup size");

    // Exactly the documented bindings, all in group 0.
    let mut globals: Vec<_> = m
        .global_variables
        .iter()
        .filter_map(|(_, g)| g.binding.as_ref().map(|b| (b.group, b.binding, g)))
        .collect();
    globals.sort_by_key(|(g, b, _)| (*g, *b));
    let want = expected(table_elem.is_some());
    assert_eq!(globals.len(), want.len(), "{name}: number of bindings");
    for ((group, binding, g), (wb, wname, wspace)) in globals.iter().zip(want) {
        assert_eq!((*group, *binding), (0, wb), "{name}: binding of {wname}");
        assert_eq!(
            g.name.as_deref(),
            Some(wname),
            "{name}: name at binding {wb}"
        );
        assert_eq!(g.space, wspace, "{name}: address space of {wname}");
        let ty = &m.types[g.ty].inner;
        if wname == "params" {
            // struct Params { n, row_stride, _pad0, _pad1: u32 }: 16 bytes
            match ty {
                naga::TypeInner::Struct { members, span } => {
                    let names: Vec<_> = members.iter().map(|m| m.name.as_deref()).collect();
                    assert_eq!(
                        names,
                        [Some("n"), Some("row_stride"), Some("_pad0"), Some("_pad1")],
                        "{name}: Params members"
                    );
                    for mem in members {
                        assert_eq!(
                            m.types[mem.ty].inner,
                            naga::TypeInner::Scalar(naga::Scalar::U32),
                            "{name}: Params member types"
                        );
                    }
                    assert_eq!(*span, 16, "{name}: Params size");
                }
                other => panic!("{name}: params is {other:?}, not a struct"),
            }
        } else {
            let elem = if wname == "table" && table_elem == Some("u32") {
                naga::Scalar::U32
            } else {
                naga::Scalar::F32
            };
            match ty {
                naga::TypeInner::Array { base, .. } => assert_eq!(
                    m.types[*base].inner,
                    naga::TypeInner::Scalar(elem),
                    "{name}: element type of {wname}"
                ),
                other => panic!("{name}: {wname} is {other:?}, not an array"),
            }
        }
    }
}

#[test]
fn every_kernel_validates_with_the_documented_interface() {
    for (name, src) in wgsl::ALL {
        assert!(
            registry::batch_kernels().any(|k| k.name() == name),
            "{name}: not a harness kernel name"
        );
        check_interface(name, src, (name == "cap-exponent").then_some("f32"));
    }
}

#[test]
fn every_custom_kernel_validates_with_the_documented_interface() {
    for (name, src, table) in wgsl::CUSTOM {
        check_interface(name, src, Some(table));
    }
}

/// The kernels that are neither registered nor custom (they serve the harness's own paths)
/// validate too, without an adapter.
#[test]
fn unlisted_kernels_validate_with_the_documented_interface() {
    for (name, src) in [
        ("sh-hvl", wgsl::SH_HVL),
        ("sh-hvl-exact", wgsl::SH_HVL_EXACT),
        ("sh-hvl-sum", wgsl::SH_HVL_SUM),
        ("lobe-chain", wgsl::LOBE_CHAIN),
    ] {
        check_interface(name, src, Some("f32"));
    }
}

#[test]
fn all_lists_every_kernel_once() {
    let mut names: Vec<_> = wgsl::ALL.iter().map(|(n, _)| *n).collect();
    names.sort_unstable();
    let mut want: Vec<_> = registry::batch_kernels().map(|k| k.name()).collect();
    want.sort_unstable();
    assert_eq!(names, want);
}
