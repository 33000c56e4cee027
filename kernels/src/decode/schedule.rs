//! The dispatches of one round, shared by the wgpu and OpenCL hosts: which
//! entry point runs with which parameters over how many workgroups.

use super::layout::{Params, Schedule, WORKGROUP};
use super::sources::DecodeModule;

/// Every entry point of the decoder kernels, in round order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Entry {
    ClearCandidates,
    AppendCandidates,
    SortBlocks,
    MergeGlobal,
    MergeLocal,
    FlagsToValues,
    ScanLocal,
    ScanAdd,
    NumberSplits,
    RingCheck,
    WingCheck,
    Apply,
    Finish,
}

impl Entry {
    pub const ALL: [Entry; 13] = [
        Entry::ClearCandidates,
        Entry::AppendCandidates,
        Entry::SortBlocks,
        Entry::MergeGlobal,
        Entry::MergeLocal,
        Entry::FlagsToValues,
        Entry::ScanLocal,
        Entry::ScanAdd,
        Entry::NumberSplits,
        Entry::RingCheck,
        Entry::WingCheck,
        Entry::Apply,
        Entry::Finish,
    ];

    /// The function name in the WGSL and OpenCL C sources.
    pub fn name(self) -> &'static str {
        match self {
            Entry::ClearCandidates => "clear_candidates",
            Entry::AppendCandidates => "append_candidates",
            Entry::SortBlocks => "sort_blocks",
            Entry::MergeGlobal => "merge_global",
            Entry::MergeLocal => "merge_local",
            Entry::FlagsToValues => "flags_to_values",
            Entry::ScanLocal => "scan_local",
            Entry::ScanAdd => "scan_add",
            Entry::NumberSplits => "number_splits",
            Entry::RingCheck => "ring_check",
            Entry::WingCheck => "wing_check",
            Entry::Apply => "apply",
            Entry::Finish => "finish",
        }
    }

    /// The step (source file) that defines it.
    pub fn module(self) -> DecodeModule {
        match self {
            Entry::ClearCandidates | Entry::AppendCandidates => DecodeModule::Candidates,
            Entry::SortBlocks | Entry::MergeGlobal | Entry::MergeLocal => DecodeModule::BitonicSort,
            Entry::FlagsToValues | Entry::ScanLocal | Entry::ScanAdd | Entry::NumberSplits => {
                DecodeModule::PrefixNumber
            }
            Entry::RingCheck | Entry::WingCheck | Entry::Apply | Entry::Finish => {
                DecodeModule::SplitApply
            }
        }
    }
}

/// One dispatch: an entry point, its parameter slot, its workgroup count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dispatch {
    pub entry: Entry,
    pub params: Params,
    pub groups: u32,
}

/// One level of a recursive block scan: scan `len` words at `base`, block
/// totals to `sums`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScanLevel {
    pub base: u32,
    pub len: u32,
    pub sums: u32,
}

/// The levels of an exclusive scan of `len` words at 0, block sums placed
/// from `scratch` on; the last level has one block, whose total is the
/// grand total (its `sums` word).
pub fn scan_plan(len: u32, scratch: u32) -> Vec<ScanLevel> {
    let mut levels = Vec::new();
    let (mut base, mut len, mut next) = (0u32, len, scratch);
    loop {
        let blocks = len.div_ceil(WORKGROUP).max(1);
        levels.push(ScanLevel {
            base,
            len,
            sums: next,
        });
        if blocks == 1 {
            return levels;
        }
        base = next;
        len = blocks;
        next += blocks;
    }
}

/// Words of scan buffer for scans of up to `len` words (values, then sums).
pub fn scan_words(len: u32) -> u64 {
    let plan = scan_plan(len, len);
    plan.last().map_or(len as u64 + 1, |l| l.sums as u64 + 1)
}

/// The bitonic network for `sort_len` (a power of two, at least 256): the
/// entry point of each step with its (k, j).
pub fn sort_schedule(sort_len: u32) -> Vec<(Entry, u32, u32)> {
    let mut steps = vec![(Entry::SortBlocks, 0, 0)];
    let mut k = 2 * WORKGROUP;
    while k <= sort_len {
        let mut j = k / 2;
        while j >= WORKGROUP {
            steps.push((Entry::MergeGlobal, k, j));
            j /= 2;
        }
        steps.push((Entry::MergeLocal, k, 0));
        k *= 2;
    }
    steps
}

fn groups(len: u32) -> u32 {
    len.div_ceil(WORKGROUP).max(1)
}

/// Every dispatch of a round whose shared parameters are `common` (n,
/// candidates, splits, sort_len, limits, schedule); scans keep their block sums from
/// word `scan_scratch` of the scan buffer on.
pub fn round_schedule(common: Params, scan_scratch: u32) -> Vec<Dispatch> {
    let mut out = Vec::new();
    let mut push = |entry: Entry, params: Params, groups: u32| {
        out.push(Dispatch {
            entry,
            params,
            groups,
        })
    };
    push(Entry::ClearCandidates, common, groups(common.sort_len));
    push(Entry::AppendCandidates, common, groups(common.n));
    // Under every-vertex (SPEC §7.3, 3.6) append_candidates writes vertex v
    // at index v: the candidates are in order without the sort.
    let sort = if common.schedule == Schedule::EveryVertex.word() {
        Vec::new()
    } else {
        sort_schedule(common.sort_len)
    };
    for (entry, k, j) in sort {
        let params = Params {
            arg0: k,
            arg1: j,
            ..common
        };
        push(entry, params, groups(common.sort_len));
    }
    push(Entry::FlagsToValues, common, groups(common.candidates));
    let flag_total = scan(&mut push, common, common.candidates, scan_scratch);
    let number = Params {
        arg0: flag_total,
        ..common
    };
    push(Entry::NumberSplits, number, groups(common.candidates));
    push(Entry::RingCheck, common, groups(common.splits));
    let triangle_total = scan(&mut push, common, common.splits, scan_scratch);
    push(Entry::WingCheck, common, groups(common.splits));
    push(Entry::Apply, common, groups(common.splits));
    let finish = Params {
        arg0: triangle_total,
        ..common
    };
    push(Entry::Finish, finish, groups(common.splits));
    out
}

/// An exclusive scan of `len` words at the start of the scan buffer;
/// returns the word that holds the total.
fn scan(push: &mut impl FnMut(Entry, Params, u32), common: Params, len: u32, scratch: u32) -> u32 {
    let plan = scan_plan(len, scratch);
    let args = |l: &ScanLevel| Params {
        arg0: l.base,
        arg1: l.len,
        arg2: l.sums,
        ..common
    };
    for l in &plan {
        push(Entry::ScanLocal, args(l), groups(l.len));
    }
    for l in plan.iter().rev().skip(1) {
        push(Entry::ScanAdd, args(l), groups(l.len));
    }
    plan.last().map_or(scratch, |l| l.sums)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_plan_recurses_to_one_block() {
        assert_eq!(
            scan_plan(10, 100),
            vec![ScanLevel {
                base: 0,
                len: 10,
                sums: 100
            }]
        );
        let plan = scan_plan(70_000, 70_000);
        assert_eq!(plan.len(), 3);
        assert_eq!(
            plan[1],
            ScanLevel {
                base: 70_000,
                len: 274,
                sums: 70_274
            }
        );
        assert_eq!(
            plan[2],
            ScanLevel {
                base: 70_274,
                len: 2,
                sums: 70_276
            }
        );
        assert_eq!(scan_words(70_000), 70_277);
    }

    #[test]
    fn sort_schedule_covers_every_stage() {
        assert_eq!(sort_schedule(256), vec![(Entry::SortBlocks, 0, 0)]);
        assert_eq!(
            sort_schedule(1024),
            vec![
                (Entry::SortBlocks, 0, 0),
                (Entry::MergeGlobal, 512, 256),
                (Entry::MergeLocal, 512, 0),
                (Entry::MergeGlobal, 1024, 512),
                (Entry::MergeGlobal, 1024, 256),
                (Entry::MergeLocal, 1024, 0),
            ]
        );
    }

    #[test]
    fn every_vertex_rounds_skip_the_sort() {
        let common = Params {
            n: 5000,
            candidates: 5000,
            splits: 100,
            sort_len: 8192,
            ..Params::default()
        };
        let entries = |schedule: Schedule| -> Vec<Entry> {
            let params = Params {
                schedule: schedule.word(),
                ..common
            };
            round_schedule(params, 5000)
                .iter()
                .map(|d| d.entry)
                .collect()
        };
        let sorting = |e: &Entry| e.module() == DecodeModule::BitonicSort;
        let split_valences = entries(Schedule::SplitValences);
        assert_eq!(
            split_valences.iter().filter(|e| sorting(e)).count(),
            sort_schedule(8192).len()
        );
        let every_vertex = entries(Schedule::EveryVertex);
        assert!(!every_vertex.iter().any(sorting));
        let unsorted: Vec<Entry> = split_valences.into_iter().filter(|e| !sorting(e)).collect();
        assert_eq!(every_vertex, unsorted);
    }

    #[test]
    fn every_entry_is_in_its_module() {
        for e in Entry::ALL {
            assert!(e.module().entry_points().contains(&e.name()), "{e:?}");
        }
    }
}
