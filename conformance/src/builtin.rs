//! Decoders compiled into the runner, run in-process.
//!
//! To add one (a C ABI, WebAssembly, wgpu or OpenCL decoder), write a
//! `fn(&[u8]) -> Outcome` that decodes through that implementation and
//! reports the state hash after the seed mesh and after every round, then
//! add a [`Builtin`] entry to [`BUILTINS`] (behind a cargo feature if it
//! needs a toolchain or device that CI machines may lack). A decoder that
//! lives in another process needs nothing here: see `run --decoder`.

use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::record::{StreamSource, read_base};
use splitstream_decoder_core::substream::Substreams;
use splitstream_decoder_core::{
    Error, Header, Inflater, LevelTable, MeshState, RecordSource, Ring, SplitRecord, layout_for,
};

use splitstream_sdk_native::threaded::{self, TwoThreadMemory};

use crate::protocol::{Outcome, Verdict};

/// A decoder the runner can call directly.
pub struct Builtin {
    pub name: &'static str,
    pub summary: &'static str,
    /// Test-only decoders are left out of `run` without `--builtin`.
    pub hidden: bool,
    pub decode: fn(&[u8]) -> Outcome,
}

/// Every built-in decoder; the visible ones make up `run`'s default list.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "decoder-core",
        summary: "the reference decoder (decoder-core's Decoder, level by level, round by round)",
        hidden: false,
        decode: decoder_core,
    },
    Builtin {
        name: "fans-ahead",
        summary: "decoder-core with the fans of each batch's flagged vertices walked ahead in lockstep at every size (the default starts at 65,536 vertices)",
        hidden: false,
        decode: fans_ahead,
    },
    Builtin {
        name: "two-threads",
        summary: "decoder-core's rounds with the split records read on a second thread (sdk-native threaded)",
        hidden: false,
        decode: two_threads,
    },
    #[cfg(feature = "gpu")]
    Builtin {
        name: "wgpu",
        summary: "decoder-core reads the stream, the rounds run on a wgpu device (sdk-native gpu, kernels' decoder); the GPU's hashes",
        hidden: false,
        decode: crate::builtin_gpu::wgpu,
    },
    #[cfg(feature = "opencl")]
    Builtin {
        name: "opencl",
        summary: "as wgpu, with the rounds on an OpenCL device (the kernels' OpenCL C port)",
        hidden: false,
        decode: crate::builtin_gpu::opencl,
    },
    // Later: "c-abi" (sdk-native), "wasm" (sdk-wasm).
    Builtin {
        name: "broken-swap",
        summary: "test only: decoder-core's pieces driven by hand with the positions of P and C swapped in every split; must fail",
        hidden: true,
        decode: broken_swap,
    },
];

/// The built-in named `name`.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// Runs a built-in, turning a panic into a broken outcome.
pub fn run_builtin(b: &Builtin, stream: &[u8]) -> Outcome {
    std::panic::catch_unwind(|| (b.decode)(stream))
        .unwrap_or_else(|_| Outcome::broken(format!("{} panicked", b.name)))
}

fn finish(hashes: Vec<u64>, result: Result<(), Error>) -> Outcome {
    Outcome {
        hashes,
        verdict: match result {
            Ok(()) => Verdict::Ok,
            Err(e) => Verdict::Error(e.class().to_string()),
        },
    }
}

/// The reference decoder through its public API.
pub fn decoder_core(stream: &[u8]) -> Outcome {
    decoder_core_with(stream, None)
}

/// decoder-core walking ahead the fans of every batch's likely flagged
/// vertices whatever the mesh's size: a speed setting that must not change
/// any state (`Decoder::set_fans_ahead_from`), which the small vectors
/// would otherwise never take.
pub fn fans_ahead(stream: &[u8]) -> Outcome {
    decoder_core_with(stream, Some(0))
}

/// [`decoder_core`], with the fans walked ahead from `fans_ahead_from`
/// vertices when given.
fn decoder_core_with(stream: &[u8], fans_ahead_from: Option<u32>) -> Outcome {
    let mut hashes = Vec::new();
    let result = (|| {
        let mut ws = OwnedWorkspace::for_stream(stream)?;
        let mut decoder = ws.decoder(stream)?;
        if let Some(from) = fans_ahead_from {
            decoder.set_fans_ahead_from(from);
        }
        while let Some(k) = decoder.next_level() {
            let bytes = decoder.level_bytes(k, stream)?;
            let mut level = decoder.begin_level(k, bytes)?;
            if k == 0 {
                hashes.push(level.state().state_hash());
            }
            while level.next_round()?.is_some() {
                hashes.push(level.state().state_hash());
            }
        }
        Ok(())
    })();
    finish(hashes, result)
}

/// decoder-core with each level's records read on a second thread
/// (`splitstream_sdk_native::threaded`).
pub fn two_threads(stream: &[u8]) -> Outcome {
    let mut hashes = Vec::new();
    let result = (|| {
        let mut ws = OwnedWorkspace::for_stream(stream)?;
        let mut decoder = ws.decoder(stream)?;
        let mut memory = TwoThreadMemory::new(decoder.state().vertex_capacity());
        // Every level through the second thread, however small.
        memory.set_two_threads_from(0);
        while let Some(k) = decoder.next_level() {
            let bytes = decoder.level_bytes(k, stream)?;
            threaded::decode_level_observed(&mut decoder, k, bytes, &mut memory, |_, state| {
                hashes.push(state.state_hash())
            })?;
        }
        Ok(())
    })();
    finish(hashes, result)
}

fn broken_swap(stream: &[u8]) -> Outcome {
    decode_by_pieces(stream, true)
}

/// Swaps the positions of P and C in every split record it passes on.
struct SwapPositions<S>(S);

impl<S: RecordSource> RecordSource for SwapPositions<S> {
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        self.0.flag(state, v)
    }

    fn likely_flags(&mut self, state: &MeshState<'_>, upcoming: &[u32]) -> u128 {
        self.0.likely_flags(state, upcoming)
    }

    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let mut record = self.0.record(state, r, ring)?;
        core::mem::swap(&mut record.position_p, &mut record.position_c);
        Ok(record)
    }
}

/// Decodes with decoder-core's public pieces, in the order of SPEC §10.3
/// (the order `Decoder` uses); with `broken`, every split record's P and C
/// positions are swapped. Without it this must agree with
/// [`decoder_core`] on every vector (a test checks it), except that it
/// reports the seed mesh's hash right after the seed as SPEC §8 says, also
/// when level 0 has no rounds and then fails its end-of-level checks, where
/// `Decoder` (which completes such a level inside `begin_level`) reports none.
pub fn decode_by_pieces(stream: &[u8], broken: bool) -> Outcome {
    let mut hashes = Vec::new();
    let result = pieces(stream, broken, &mut hashes);
    finish(hashes, result)
}

fn pieces(stream: &[u8], broken: bool, hashes: &mut Vec<u64>) -> Result<(), Error> {
    let header = Header::parse(stream)?;
    let table = LevelTable::parse(stream, &header)?;
    let layout = layout_for(&header, &table, header.level_count - 1);
    if layout.total != header.workspace_bytes {
        return Err(Error::InvalidHeader(
            "declared workspace size differs from SPEC §9",
        ));
    }
    let len = usize::try_from(layout.bytes_unaligned()).map_err(|_| Error::CapacityExceeded)?;
    let mut workspace = vec![0u8; len];
    let (memory, mut buffers) = layout.carve(&mut workspace)?;
    let mut state = MeshState::new(memory, header.bits, header.schedule);
    let mut inflater = Box::new(Inflater::new());
    let mut ring = Box::new(Ring::default());
    for k in 0..header.level_count {
        let info = table.get(k);
        let bytes = usize::try_from(info.offset)
            .ok()
            .and_then(|s| stream.get(s..s.checked_add(info.length as usize)?))
            .ok_or(Error::Truncated)?;
        // SPEC §5.1: the level header against the table entry.
        let is_base = k == 0;
        let level_header = table.level_header(k, bytes, header.level_rules())?;
        // SPEC §7.6: no split may take the level past its triangle count;
        // §6.1 (3.10): the split-history bits start the level at 0.
        state.start_level(info.triangle_count);
        let rounds = level_header.round_count;
        if is_base {
            // SPEC §6.3: the seed mesh (substreams 8..=10) comes first.
            let slots = buffers.each_mut().map(|b| &mut **b);
            let mut seed = Substreams::open(
                bytes,
                level_header,
                substream::BASE_POSITIONS,
                slots,
                &mut inflater,
                header.lane_count,
            );
            let (v, t) = (level_header.seed_vertices, level_header.seed_triangles);
            read_base(&mut state, &mut seed, v, t)?;
            // SPEC §8, §10.3: the seed's hash comes before the rounds and
            // before the end-of-level checks.
            hashes.push(state.state_hash());
        }
        let slots = buffers.each_mut().map(|b| &mut **b);
        let mut subs = Substreams::open(
            bytes,
            level_header,
            substream::FLAGS,
            slots,
            &mut inflater,
            header.lane_count,
        );
        let mut splits = level_header.split_counts();
        for _ in 0..rounds {
            let declared = splits.next().unwrap_or(0);
            let source = StreamSource::new(&mut subs, header.position_mode);
            let result = if broken {
                state.run_round(declared, &mut SwapPositions(source), &mut ring)
            } else {
                let mut source = source;
                state.run_round(declared, &mut source, &mut ring)
            };
            result?;
            hashes.push(state.state_hash());
        }
        // SPEC §7.6: end of level.
        subs.finish()?;
        if state.vertex_count() != info.vertex_count
            || state.triangle_count() != info.triangle_count
        {
            return Err(Error::LevelCountMismatch);
        }
    }
    Ok(())
}
