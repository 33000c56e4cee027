//! The decoder's WGSL modules: each step's file with the shared prelude
//! (WGSL has no includes) and its entry points.

pub const COMMON: &str = include_str!("common.wgsl");
pub const CANDIDATES: &str = include_str!("candidates.wgsl");
pub const BITONIC_SORT: &str = include_str!("bitonic_sort.wgsl");
pub const PREFIX_NUMBER: &str = include_str!("prefix_number.wgsl");
pub const SPLIT_APPLY: &str = include_str!("split_apply.wgsl");

/// The OpenCL C port, one file per step as the WGSL.
pub mod opencl {
    pub const COMMON: &str = include_str!("common.cl");
    pub const CANDIDATES: &str = include_str!("candidates.cl");
    pub const BITONIC_SORT: &str = include_str!("bitonic_sort.cl");
    pub const PREFIX_NUMBER: &str = include_str!("prefix_number.cl");
    pub const SPLIT_APPLY: &str = include_str!("split_apply.cl");
}

/// The whole OpenCL program of the decoder: prelude, then every step.
pub fn opencl_program() -> String {
    use opencl::*;
    [COMMON, CANDIDATES, BITONIC_SORT, PREFIX_NUMBER, SPLIT_APPLY].concat()
}

/// One step of a round, one WGSL file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DecodeModule {
    Candidates,
    BitonicSort,
    PrefixNumber,
    SplitApply,
}

impl DecodeModule {
    pub const ALL: [DecodeModule; 4] = [
        DecodeModule::Candidates,
        DecodeModule::BitonicSort,
        DecodeModule::PrefixNumber,
        DecodeModule::SplitApply,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DecodeModule::Candidates => "candidates.wgsl",
            DecodeModule::BitonicSort => "bitonic_sort.wgsl",
            DecodeModule::PrefixNumber => "prefix_number.wgsl",
            DecodeModule::SplitApply => "split_apply.wgsl",
        }
    }

    /// The module's full source: prelude, then the step.
    pub fn source(self) -> String {
        let body = match self {
            DecodeModule::Candidates => CANDIDATES,
            DecodeModule::BitonicSort => BITONIC_SORT,
            DecodeModule::PrefixNumber => PREFIX_NUMBER,
            DecodeModule::SplitApply => SPLIT_APPLY,
        };
        [COMMON, body].concat()
    }

    /// Compute entry points, in the order a round dispatches them.
    pub fn entry_points(self) -> &'static [&'static str] {
        match self {
            DecodeModule::Candidates => &["clear_candidates", "append_candidates"],
            DecodeModule::BitonicSort => &["sort_blocks", "merge_global", "merge_local"],
            DecodeModule::PrefixNumber => {
                &["flags_to_values", "scan_local", "scan_add", "number_splits"]
            }
            DecodeModule::SplitApply => &["ring_check", "wing_check", "apply", "finish"],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DecodeModule;

    /// Every module parses and validates with naga (no GPU needed), and
    /// declares exactly the entry points the host dispatches.
    #[test]
    fn every_module_validates_with_naga() {
        for m in DecodeModule::ALL {
            let source = m.source();
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}: {}", m.name(), e.emit_to_string(&source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::empty(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}: {}", m.name(), e.emit_to_string(&source)));
            let mut names: Vec<&str> = module
                .entry_points
                .iter()
                .map(|e| e.name.as_str())
                .collect();
            names.sort_unstable();
            let mut expected = m.entry_points().to_vec();
            expected.sort_unstable();
            assert_eq!(names, expected, "{}", m.name());
        }
    }
}
