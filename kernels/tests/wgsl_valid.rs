//! Every WGSL module parses and validates with naga (no GPU needed), every
//! kernel's entry point exists, and the bindings each entry point uses are
//! exactly the ones the host binds (`Kernel::slots`): wgpu derives the
//! pipeline layout from that use, so a mismatch would fail at bind time.

use naga::valid::{Capabilities, ValidationFlags, Validator};
use splitstream_kernels::encode::{Kernel, WgslModule};

fn parse(module: WgslModule) -> (naga::Module, naga::valid::ModuleInfo) {
    let source = module.source();
    let parsed = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}: {}", module.name(), e.emit_to_string(&source)));
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&parsed)
        .unwrap_or_else(|e| panic!("{}: {}", module.name(), e.emit_to_string(&source)));
    (parsed, info)
}

#[test]
fn every_module_validates() {
    for module in WgslModule::ALL {
        parse(module);
    }
}

#[test]
fn entry_points_bind_what_the_host_binds() {
    for kernel in Kernel::ALL {
        let (module, info) = parse(kernel.module());
        let index = module
            .entry_points
            .iter()
            .position(|e| e.name == kernel.entry())
            .unwrap_or_else(|| {
                panic!(
                    "{} has no entry point {}",
                    kernel.module().name(),
                    kernel.entry()
                )
            });
        let used = info.get_entry_point(index);
        let mut bindings: Vec<u32> = module
            .global_variables
            .iter()
            .filter(|(handle, _)| !used[*handle].is_empty())
            .filter_map(|(_, var)| var.binding.as_ref().map(|b| b.binding))
            .collect();
        bindings.sort_unstable();
        let expected: Vec<u32> = kernel.slots().iter().map(|&s| s as u32).collect();
        assert_eq!(bindings, expected, "bindings of {}", kernel.entry());
    }
}

#[test]
fn workgroup_size_matches_the_host() {
    for module in WgslModule::ALL {
        let (parsed, _) = parse(module);
        for entry in &parsed.entry_points {
            assert_eq!(
                entry.workgroup_size,
                [splitstream_kernels::encode::layout::GROUP, 1, 1],
                "{}",
                entry.name
            );
        }
    }
}
