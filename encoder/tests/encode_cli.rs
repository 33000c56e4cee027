//! `splitstream encode` and `decode` from the command line: the position
//! mode chosen for a raster, the raster's lattice kept exactly, and one
//! clear line for bad streams and arguments.

mod cli;

use std::path::PathBuf;

use cli::{one_line_error, splitstream, succeeded};

fn temp(name: &str, contents: &str) -> PathBuf {
    cli::temp("encode-cli", name, contents)
}

/// A 12 x 10 ESRI ASCII raster, 30 m cells, heights in whole metres.
fn raster() -> PathBuf {
    let mut s = String::from(
        "ncols 12\nnrows 10\nxllcorner 500000\nyllcorner 4100000\ncellsize 30\nNODATA_value -9999\n",
    );
    for r in 0..10 {
        let row: Vec<String> = (0..12)
            .map(|c| format!("{}", 200 + (r * 7 + c * 13) % 23 + r * c / 4))
            .collect();
        s.push_str(&row.join(" "));
        s.push('\n');
    }
    temp("raster.asc", &s)
}

/// The raster of [`raster`] and its stream, encoded with the defaults into
/// `name` beside it.
fn encoded_raster(name: &str) -> (PathBuf, PathBuf) {
    let input = raster();
    let stream = input.with_file_name(name);
    succeeded(&splitstream(&[
        "encode",
        input.to_str().unwrap(),
        "-o",
        stream.to_str().unwrap(),
    ]));
    (input, stream)
}

/// The `v x y z` lines of an OBJ file.
fn obj_positions(path: &PathBuf) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn a_raster_is_encoded_constrained_and_decodes_exactly() {
    let input = raster();
    let stream = input.with_file_name("raster.sps");
    let out = splitstream(&[
        "encode",
        input.to_str().unwrap(),
        "-o",
        stream.to_str().unwrap(),
    ]);
    let stdout = succeeded(&out);
    assert!(
        stdout.contains("positions: constrained; x, y, z on the input's own lattice (exact)"),
        "{stdout}"
    );
    let decoded = input.with_file_name("raster.obj");
    succeeded(&splitstream(&[
        "decode",
        stream.to_str().unwrap(),
        "-o",
        decoded.to_str().unwrap(),
    ]));
    let positions = obj_positions(&decoded);
    assert_eq!(positions.len(), 120);
    // Every sample comes back on its cell and at its whole-metre height.
    let (x0, y0) = positions
        .iter()
        .fold((f64::MAX, f64::MAX), |(x, y), p| (x.min(p[0]), y.min(p[1])));
    let on_lattice = |v: f64| (v - v.round()).abs() < 1e-6;
    for p in &positions {
        assert!(on_lattice((p[0] - x0) / 30.0), "{p:?}");
        assert!(on_lattice((p[1] - y0) / 30.0), "{p:?}");
        assert!(on_lattice(p[2]), "{p:?}");
    }
    // Told to ignore the lattice, the same raster stays constrained, off
    // the lattice; optimal mode is asked for by name.
    let encode_with = |extra: &[&str]| {
        let mut args = vec![
            "encode",
            input.to_str().unwrap(),
            "-o",
            stream.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        succeeded(&splitstream(&args))
    };
    let ignored = encode_with(&["--lattice", "ignore"]);
    assert!(ignored.contains("positions: constrained\n"), "{ignored}");
    let optimal = encode_with(&["--position", "optimal"]);
    assert!(optimal.contains("positions: optimal\n"), "{optimal}");
}

#[test]
fn bad_streams_and_arguments_get_one_line_naming_the_file() {
    let (input, stream) = encoded_raster("for-errors.sps");
    let s = stream.to_str().unwrap();
    let bytes = std::fs::read(&stream).unwrap();
    // Cut: every reader that needs the whole stream names the file and
    // the problem; `info` describes the prefix.
    let cut = input.with_file_name("cut.sps");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let c = cut.to_str().unwrap();
    let decoded = input.with_file_name("cut.ply");
    let d = decoded.to_str().unwrap();
    for args in [vec!["verify", c], vec!["decode", c, "-o", d]] {
        let err = one_line_error(&splitstream(&args));
        assert!(
            err.contains("cut.sps: ") && err.contains("truncated"),
            "{args:?}: {err}"
        );
    }
    let described = succeeded(&splitstream(&["info", c]));
    assert!(described.contains("truncated: levels "), "{described}");
    // Cut inside level 0: no field table (it had no vertex to count bits
    // per, and printed NaN).
    let head_len = splitstream_decoder_core::Header::parse(&bytes)
        .unwrap()
        .head_len();
    let early = input.with_file_name("cut-in-level-0.sps");
    std::fs::write(&early, &bytes[..head_len + 10]).unwrap();
    let described = succeeded(&splitstream(&["info", early.to_str().unwrap()]));
    assert!(described.contains("no level is whole"), "{described}");
    assert!(
        !described.contains("NaN") && !described.contains("bits/vertex\n"),
        "{described}"
    );
    let garbage = temp("garbage.sps", "not a stream at all");
    let err = one_line_error(&splitstream(&["info", garbage.to_str().unwrap()]));
    assert!(err.contains("garbage.sps: not a splitstream file"), "{err}");
    let out = input.with_file_name("out.ply");
    let o = out.to_str().unwrap();
    let err = one_line_error(&splitstream(&["decode", s, "-o", o, "--level", "99"]));
    assert!(err.contains("--level 99"), "{err}");
    let err = one_line_error(&splitstream(&["decode", s, "-o", "out.xyz"]));
    assert!(err.contains("out.xyz"), "{err}");
    let err = one_line_error(&splitstream(&["decode", s, "-o", o, "--threads", "3"]));
    assert!(err.contains("--threads"), "{err}");
    let err = one_line_error(&splitstream(&["decode", c, "-o", d, "--threads", "2"]));
    assert!(
        err.contains("cut.sps: ") && err.contains("truncated"),
        "{err}"
    );
    // A negative error is a value refused for its reason, not an unknown
    // flag.
    let raster = input.to_str().unwrap();
    let negative = input.with_file_name("negative-error.sps");
    let err = one_line_error(&splitstream(&[
        "encode",
        raster,
        "-o",
        negative.to_str().unwrap(),
        "--max-error",
        "-1",
    ]));
    assert!(
        err.contains("--max-error -1 is not a finite error"),
        "{err}"
    );
}

#[test]
fn two_threads_decode_the_same_mesh() {
    let (input, stream) = encoded_raster("for-threads.sps");
    let s = stream.to_str().unwrap();
    let one = input.with_file_name("one-thread.obj");
    let two = input.with_file_name("two-threads.obj");
    let a = succeeded(&splitstream(&[
        "decode",
        s,
        "-o",
        one.to_str().unwrap(),
        "--threads",
        "1",
    ]));
    // Two threads are the default.
    let b = succeeded(&splitstream(&["decode", s, "-o", two.to_str().unwrap()]));
    let tail = |out: &str| out.split(": ").nth(1).unwrap().to_string();
    assert_eq!(tail(&a), tail(&b));
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());
}

#[test]
fn a_prefix_of_the_stream_decodes_to_its_last_whole_level() {
    let (input, stream) = encoded_raster("for-prefix.sps");
    let s = stream.to_str().unwrap();
    let bytes = std::fs::read(&stream).unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
    let levels = doc["levels"].as_array().unwrap();
    assert!(levels.len() >= 3, "{doc}");
    assert_eq!(doc["levels_in_file"].as_u64(), Some(levels.len() as u64));
    let hash = |stdout: &str| {
        stdout
            .split("state hash ")
            .nth(1)
            .unwrap()
            .trim()
            .to_string()
    };
    let out = input.with_file_name("prefix.obj");
    let o = out.to_str().unwrap();
    // Cut one byte before the end of level k (k ≥ 1): levels 0..k are whole.
    for (k, level) in levels.iter().enumerate().skip(1) {
        let end = (level["offset"].as_u64().unwrap() + level["length"].as_u64().unwrap()) as usize;
        let cut = input.with_file_name(format!("prefix-{k}.sps"));
        std::fs::write(&cut, &bytes[..end - 1]).unwrap();
        let c = cut.to_str().unwrap();
        let partial = succeeded(&splitstream(&["decode", c, "-o", o, "--available"]));
        assert!(
            partial.contains(&format!("level {} (levels {k}..=", k - 1)),
            "{partial}"
        );
        let whole = succeeded(&splitstream(&[
            "decode",
            s,
            "-o",
            o,
            "--level",
            &(k - 1).to_string(),
        ]));
        assert_eq!(hash(&partial), hash(&whole), "prefix up to level {k}");
        let described: serde_json::Value =
            serde_json::from_str(&succeeded(&splitstream(&["info", c, "--json"]))).unwrap();
        assert_eq!(described["levels_in_file"].as_u64(), Some(k as u64));
        // Bits per vertex of what the file holds: levels 0..k's bytes over
        // level k - 1's vertices.
        let held = &levels[k - 1];
        assert_eq!(described["vertices_in_file"], held["vertices"]);
        let bytes = held["offset"].as_f64().unwrap() + held["length"].as_f64().unwrap();
        let bpv = described["bits_per_vertex"].as_f64().unwrap();
        assert!((bpv - 8.0 * bytes / held["vertices"].as_f64().unwrap()).abs() < 1e-9);
    }
    // The whole file: `--available` changes nothing.
    let all = succeeded(&splitstream(&["decode", s, "-o", o, "--available"]));
    let whole = succeeded(&splitstream(&["decode", s, "-o", o]));
    assert_eq!(all, whole);
    // Not even level 0: one line, and --codecs needs every level.
    let head = input.with_file_name("prefix-head.sps");
    std::fs::write(
        &head,
        &bytes[..levels[0]["offset"].as_u64().unwrap() as usize + 1],
    )
    .unwrap();
    let h = head.to_str().unwrap();
    let err = one_line_error(&splitstream(&["decode", h, "-o", o, "--available"]));
    assert!(err.contains("no whole level in the file"), "{err}");
    let err = one_line_error(&splitstream(&["info", h, "--codecs"]));
    assert!(err.contains("--codecs"), "{err}");
    let described = succeeded(&splitstream(&["info", h]));
    assert!(
        described.contains("no whole level in the file"),
        "{described}"
    );
}

#[test]
fn info_gives_the_memory_each_prefix_of_levels_needs() {
    let (_, stream) = encoded_raster("for-info.sps");
    let s = stream.to_str().unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
    let memory: Vec<u64> = doc["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["workspace_bytes"].as_u64().unwrap())
        .collect();
    assert!(!memory.is_empty());
    // Each level needs at least the memory of the ones before it, and all
    // of them the header's workspace (SPEC §9).
    assert!(memory.windows(2).all(|w| w[0] <= w[1]), "{memory:?}");
    assert_eq!(memory.last().copied(), doc["workspace_bytes"].as_u64());
}

#[test]
fn info_counts_each_fields_chunks() {
    let (_, stream) = encoded_raster("for-chunks.sps");
    let s = stream.to_str().unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
    let levels = doc["levels"].as_array().unwrap().len() as u64;
    let fields = doc["fields"].as_object().unwrap();
    for (name, field) in fields {
        let (bytes, chunks) = (field["bytes"].as_u64(), field["chunks"].as_u64());
        match bytes {
            // A field with bytes has at least one chunk in every level
            // that codes it: the seed mesh's in level 0 only, the rounds'
            // in at most every level.
            Some(b) if b > 0 => {
                let chunks = chunks.unwrap();
                assert!((1..=levels * 64).contains(&chunks), "{name}: {field}");
            }
            _ => assert_eq!(chunks, Some(0), "{name}: {field}"),
        }
    }
    // The text form has the column too.
    let text = succeeded(&splitstream(&["info", s]));
    assert!(text.contains("raw bytes/values  chunks  codecs"), "{text}");
}

#[test]
fn info_gives_each_fields_bytes_by_level() {
    let (_, stream) = encoded_raster("by-level.sps");
    let s = stream.to_str().unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
    let levels = doc["levels"].as_array().unwrap();
    // Each field's bytes over the levels sum to its total, and each level's
    // fields stay within the level's bytes (the rest is its framing).
    for (name, field) in doc["fields"].as_object().unwrap() {
        let by_level: u64 = levels
            .iter()
            .map(|l| l["field_bytes"][name].as_u64().unwrap())
            .sum();
        assert_eq!(Some(by_level), field["bytes"].as_u64(), "{name}");
    }
    for level in levels {
        let fields: u64 = level["field_bytes"]
            .as_object()
            .unwrap()
            .values()
            .map(|b| b.as_u64().unwrap())
            .sum();
        assert!(
            fields > 0 && fields < level["length"].as_u64().unwrap(),
            "{level}"
        );
    }
    let text = succeeded(&splitstream(&["info", s, "--by-level"]));
    assert!(text.contains("bytes by level:    level 0"), "{text}");
    assert!(text.contains("bits/new v"), "{text}");
    // A prefix holding level 0 only: later levels have no field bytes.
    let bytes = std::fs::read(&stream).unwrap();
    let level1 = levels[1]["offset"].as_u64().unwrap() as usize;
    let prefix = stream.with_file_name("by-level-prefix.sps");
    std::fs::write(&prefix, &bytes[..level1]).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&succeeded(&splitstream(&[
        "info",
        prefix.to_str().unwrap(),
        "--json",
    ])))
    .unwrap();
    assert!(doc["levels"][0]["field_bytes"].is_object());
    assert!(doc["levels"][1]["field_bytes"].is_null());
}

#[test]
fn a_decoded_glb_encodes_back_to_the_same_stream() {
    // Geographic-sized coordinates: the GLB keeps them in the node's
    // translation (f64 JSON) and positions relative to it (f32), so at 14
    // bits the quantized positions come back exactly, and so does the
    // stream. (The lattice is ignored: f32 positions are a hair off it.)
    let input = raster();
    let stream = input.with_file_name("glb-raster.sps");
    let s = stream.to_str().unwrap();
    let encode = |from: &str, to: &str| {
        succeeded(&splitstream(&[
            "encode",
            from,
            "-o",
            to,
            "--lattice",
            "ignore",
        ]))
    };
    encode(input.to_str().unwrap(), s);
    let glb = input.with_file_name("glb-raster.glb");
    succeeded(&splitstream(&["decode", s, "-o", glb.to_str().unwrap()]));
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
    let again = input.with_file_name("glb-raster-again.sps");
    encode(glb.to_str().unwrap(), again.to_str().unwrap());
    assert!(std::fs::read(&stream).unwrap() == std::fs::read(&again).unwrap());
    // A wrong output extension names all three.
    let err = one_line_error(&splitstream(&["decode", s, "-o", "out.gltf"]));
    assert!(err.contains("must end in .ply, .obj or .glb"), "{err}");
}

/// One level holds the whole mesh: `--base-vertices` is then noted as
/// having no effect, and the stream is the whole raster in level 0.
#[test]
fn one_level_notes_that_the_base_size_has_no_effect() {
    let input = raster();
    let stream = input.with_file_name("one-level.sps");
    let out = splitstream(&[
        "encode",
        input.to_str().unwrap(),
        "-o",
        stream.to_str().unwrap(),
        "--levels",
        "1",
        "--base-vertices",
        "20",
    ]);
    let stdout = succeeded(&out);
    assert!(stdout.contains("120 vertices"), "{stdout}");
    assert!(stdout.contains(", 1 levels,"), "{stdout}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("note: --base-vertices has no effect with --levels 1"),
        "{stderr}"
    );
}

#[test]
fn gpu_bench_can_leave_out_the_decoder_table() {
    let out = succeeded(&splitstream(&[
        "gpu-bench",
        "--sides",
        "24",
        "--backends",
        "cpu,sequential",
        "--skip-decoder",
    ]));
    assert!(out.contains("| 24x24 | 576 |"), "{out}");
    assert!(
        out.contains("| cpu |") && out.contains("| sequential |"),
        "{out}"
    );
    assert!(!out.contains("GPU decoder"), "{out}");
    let err = one_line_error(&splitstream(&["gpu-bench", "--sides", "1"]));
    assert!(err.contains("--sides: 1"), "{err}");
}

/// A closed torus of `rings` x `sides` vertices, as OFF text.
fn torus_off(rings: usize, sides: usize) -> String {
    let mut s = format!("OFF\n{} {} 0\n", rings * sides, 2 * rings * sides);
    for i in 0..rings {
        let u = i as f64 / rings as f64 * std::f64::consts::TAU;
        for j in 0..sides {
            let v = j as f64 / sides as f64 * std::f64::consts::TAU;
            // A little unevenness, so the collapses do not all tie.
            let r = 1.0 + 0.05 * ((3 * i + 5 * j) % 7) as f64 / 7.0;
            let (x, y) = ((3.0 + r * v.cos()) * u.cos(), (3.0 + r * v.cos()) * u.sin());
            s.push_str(&format!("{x} {y} {}\n", r * v.sin()));
        }
    }
    let at = |i: usize, j: usize| (i % rings) * sides + j % sides;
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            s.push_str(&format!("3 {a} {b} {c}\n3 {a} {c} {d}\n"));
        }
    }
    s
}

#[test]
fn bench_dumps_the_quality_rows_meshes_and_says_where_the_farthest_samples_lie() {
    // The bench reads its inputs by name from `--data`: a torus stands in
    // for armadillo.
    let data = temp("armadillo.off", &torus_off(32, 16));
    let data = data.parent().unwrap();
    let dump = data.join("bench-dump");
    let out = succeeded(&splitstream(&[
        "bench",
        "--data",
        data.to_str().unwrap(),
        "--only",
        "armadillo",
        "--skip-throughput",
        "--dump",
        dump.to_str().unwrap(),
    ]));
    assert!(out.contains("| armadillo | 25.00 % (128 v) |"), "{out}");
    assert!(out.contains("### The largest distances"), "{out}");
    let rows: Vec<&str> = out
        .lines()
        .filter(|l| {
            l.starts_with("| armadillo | 25.00 % |") || l.starts_with("| armadillo | 6.25 % |")
        })
        .collect();
    assert_eq!(rows.len(), 2, "{out}");
    for row in rows {
        assert!(row.contains(") on the "), "{row}");
    }
    for percent in ["25", "6.25"] {
        for mesh in ["reference", "parallel", "sequential"] {
            let ply = dump.join(format!("armadillo-{percent}-{mesh}.ply"));
            let bytes = std::fs::read(&ply).unwrap_or_else(|e| panic!("{}: {e}", ply.display()));
            assert!(bytes.starts_with(b"ply\n"), "{}", ply.display());
        }
    }
}

#[test]
fn verify_prints_the_state_hash_after_the_last_round() {
    let (_, stream) = encoded_raster("for-verify.sps");
    let out = succeeded(&splitstream(&["verify", stream.to_str().unwrap()]));
    let bytes = std::fs::read(&stream).unwrap();
    let mesh = splitstream_decoder_core::owned::decode_all(&bytes, true).unwrap();
    let hash = format!("state hash {:016x}", mesh.round_hashes.last().unwrap());
    assert!(out.contains(&hash), "{out}");
    let rounds = format!("{} rounds", mesh.round_hashes.len() - 1);
    assert!(out.contains(&rounds), "{out}");
}

/// `--schedule` picks how the stream says which vertices split (SPEC §3.2):
/// both decode to the same mesh, `info` names the schedule, the default is
/// `every-vertex` (format 3.6) and `split-valences` keeps the minor
/// version older decoders read. `transcode` goes either way and keeps the
/// mesh.
/// The compact framing (format 3.12, the default: compact level table
/// and level headers), `compact-levels` (3.11) and the fixed one decode to
/// the same mesh; each is smaller than the next by what its table and
/// level headers save and nothing else (the payloads are the same bytes),
/// `info` names it, and `transcode` converts either way.
#[test]
fn every_framing_decodes_to_the_same_mesh_and_compact_is_smallest() {
    let (input, compact) = encoded_raster("framing-compact.sps");
    let fixed = input.with_file_name("framing-fixed.sps");
    let levels = input.with_file_name("framing-compact-levels.sps");
    let (i, c, f, l) = (
        input.to_str().unwrap(),
        compact.to_str().unwrap(),
        fixed.to_str().unwrap(),
        levels.to_str().unwrap(),
    );
    succeeded(&splitstream(&["encode", i, "-o", f, "--framing", "fixed"]));
    succeeded(&splitstream(&[
        "encode",
        i,
        "-o",
        l,
        "--framing",
        "compact-levels",
    ]));
    let bytes = |p: &PathBuf| std::fs::read(p).unwrap();
    let header = |p: &PathBuf| splitstream_decoder_core::Header::parse(&bytes(p)).unwrap();
    use splitstream_decoder_core::Framing;
    assert_eq!(header(&compact).framing, Framing::Compact);
    assert_eq!(header(&compact).version_minor, 12);
    assert_eq!(header(&levels).framing, Framing::CompactLevels);
    assert_eq!(header(&levels).version_minor, 11);
    assert_eq!(header(&fixed).framing, Framing::Fixed);
    assert!(header(&fixed).version_minor < 11);
    let (lc, ll, lf) = (
        bytes(&compact).len(),
        bytes(&levels).len(),
        bytes(&fixed).len(),
    );
    assert!(
        lc < ll && ll < lf,
        "compact {lc} bytes, compact-levels {ll}, fixed {lf}"
    );
    // The levels' bytes are the same under either compact framing.
    let head = |p: &PathBuf| header(p).head_len();
    assert_eq!(
        bytes(&compact)[head(&compact)..],
        bytes(&levels)[head(&levels)..]
    );
    assert!(succeeded(&splitstream(&["info", c])).contains("framing: compact (level table"));
    assert!(succeeded(&splitstream(&["info", l])).contains("framing: compact-levels"));
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", f, "--json"]))).unwrap();
    assert_eq!(doc["framing"], "fixed", "{doc}");
    // What a client fetches first: the header and the (compact) table.
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", c, "--json"]))).unwrap();
    assert_eq!(doc["head_len"], head(&compact), "{doc}");
    let mesh = |p: &PathBuf| {
        let m = splitstream_decoder_core::owned::decode_all(&bytes(p), false).unwrap();
        (m.positions, m.triangles)
    };
    assert_eq!(mesh(&compact), mesh(&fixed));
    assert_eq!(mesh(&levels), mesh(&fixed));
    // Transcoded to another framing, each is the other's bytes.
    let to_fixed = input.with_file_name("framing-to-fixed.sps");
    let to_compact = input.with_file_name("framing-to-compact.sps");
    let (tf, tc) = (to_fixed.to_str().unwrap(), to_compact.to_str().unwrap());
    succeeded(&splitstream(&[
        "transcode",
        c,
        "-o",
        tf,
        "--framing",
        "fixed",
    ]));
    succeeded(&splitstream(&["transcode", f, "-o", tc]));
    assert_eq!(mesh(&to_fixed), mesh(&compact));
    assert_eq!(bytes(&to_compact), bytes(&compact));
    assert_eq!(bytes(&to_fixed).len(), lf);
    let to_levels = input.with_file_name("framing-to-compact-levels.sps");
    let tl = to_levels.to_str().unwrap();
    succeeded(&splitstream(&[
        "transcode",
        c,
        "-o",
        tl,
        "--framing",
        "compact-levels",
    ]));
    assert_eq!(bytes(&to_levels), bytes(&levels));
}

#[test]
fn both_schedules_decode_to_the_same_mesh() {
    let (input, every) = encoded_raster("schedule-every.sps");
    let split = input.with_file_name("schedule-split.sps");
    let (i, e, s) = (
        input.to_str().unwrap(),
        every.to_str().unwrap(),
        split.to_str().unwrap(),
    );
    succeeded(&splitstream(&[
        "encode",
        i,
        "-o",
        s,
        "--schedule",
        "split-valences",
        // Static tables and the fixed framing: no 3.9 or 3.11 feature, so
        // older decoders read it.
        "--tables",
        "static",
        "--framing",
        "fixed",
    ]));
    let header =
        |p: &PathBuf| splitstream_decoder_core::Header::parse(&std::fs::read(p).unwrap()).unwrap();
    use splitstream_decoder_core::Schedule;
    assert_eq!(header(&every).schedule, Schedule::EveryVertex);
    // 3.12: the compact framing, the default (SPEC §1).
    assert_eq!(header(&every).version_minor, 12);
    assert_eq!(header(&split).schedule, Schedule::SplitValences);
    assert!(header(&split).version_minor < 6);
    assert!(succeeded(&splitstream(&["info", e])).contains("schedule: every-vertex"));
    let doc: serde_json::Value =
        serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
    assert_eq!(doc["schedule"], "split-valences", "{doc}");
    let mesh = |p: &PathBuf| {
        let m =
            splitstream_decoder_core::owned::decode_all(&std::fs::read(p).unwrap(), false).unwrap();
        (m.positions, m.triangles)
    };
    assert_eq!(mesh(&every), mesh(&split));
    // Across schedules in both directions.
    let back = input.with_file_name("schedule-back.sps");
    let b = back.to_str().unwrap();
    succeeded(&splitstream(&[
        "transcode",
        e,
        "-o",
        b,
        "--schedule",
        "split-valences",
    ]));
    assert_eq!(header(&back).schedule, Schedule::SplitValences);
    assert_eq!(mesh(&back), mesh(&every));
    let forth = input.with_file_name("schedule-forth.sps");
    let f = forth.to_str().unwrap();
    succeeded(&splitstream(&["transcode", s, "-o", f]));
    assert_eq!(header(&forth).schedule, Schedule::EveryVertex);
    assert_eq!(mesh(&forth), mesh(&split));
}

/// `--records` (format 3.7) and `--ties` (3.8): positions first forced on
/// a raster, under each tie rule, decodes to the mesh the wings-first
/// stream gives, `info` names each level's record order (byte 11, the tie
/// rule included), and positions first where a level could not declare
/// it is one clear line.
#[test]
fn records_read_positions_first_decode_to_the_same_mesh() {
    let input = raster();
    let i = input.to_str().unwrap();
    let mut meshes = Vec::new();
    for (records, ties, name) in [
        ("wings-first", "auto", "wings-first"),
        ("positions-first", "ring", "positions-first"),
        ("positions-first", "rising", "positions-first-rising"),
        ("positions-first", "falling", "positions-first-falling"),
    ] {
        let stream = input.with_file_name(format!("records-{name}.sps"));
        let s = stream.to_str().unwrap();
        succeeded(&splitstream(&[
            "encode",
            i,
            "-o",
            s,
            "--records",
            records,
            "--ties",
            ties,
            // Static tables and the fixed framing: the minor version is
            // the record order's.
            "--tables",
            "static",
            "--framing",
            "fixed",
        ]));
        let doc: serde_json::Value =
            serde_json::from_str(&succeeded(&splitstream(&["info", s, "--json"]))).unwrap();
        for level in doc["levels"].as_array().unwrap() {
            assert_eq!(level["record_order"], name, "{level}");
        }
        // 3.7 unless a level breaks its ties by a diagonal.
        let minor = if name.ends_with("ing") { 8 } else { 7 };
        if records == "positions-first" {
            assert_eq!(doc["version"], format!("3.{minor}"), "{name}");
        }
        let text = succeeded(&splitstream(&["info", s]));
        assert!(text.contains(name), "{text}");
        let decoded = input.with_file_name(format!("records-{records}.obj"));
        succeeded(&splitstream(&[
            "decode",
            s,
            "-o",
            decoded.to_str().unwrap(),
        ]));
        meshes.push(std::fs::read_to_string(&decoded).unwrap());
    }
    assert!(meshes.iter().all(|m| *m == meshes[0]));
    let out = input.with_file_name("records-optimal.sps");
    let err = one_line_error(&splitstream(&[
        "encode",
        i,
        "-o",
        out.to_str().unwrap(),
        "--records",
        "positions-first",
        "--position",
        "optimal",
    ]));
    assert!(err.contains("--records positions-first"), "{err}");
}

/// Without `--lanes`, a small mesh gets one rANS lane (lanes only cost
/// bytes there), and `transcode` chooses the same way; `--lanes` sets it.
#[test]
fn small_meshes_get_one_lane_unless_asked() {
    let (_, stream) = encoded_raster("lanes-default.sps");
    let lanes = |p: &PathBuf| {
        splitstream_decoder_core::Header::parse(&std::fs::read(p).unwrap())
            .unwrap()
            .lane_count
    };
    assert_eq!(lanes(&stream), 1);
    let input = raster();
    let four = input.with_file_name("lanes-four.sps");
    succeeded(&splitstream(&[
        "encode",
        input.to_str().unwrap(),
        "-o",
        four.to_str().unwrap(),
        "--lanes",
        "4",
    ]));
    assert_eq!(lanes(&four), 4);
    let back = input.with_file_name("lanes-transcoded.sps");
    succeeded(&splitstream(&[
        "transcode",
        four.to_str().unwrap(),
        "-o",
        back.to_str().unwrap(),
    ]));
    assert_eq!(lanes(&back), 1);
    assert_eq!(
        std::fs::read(&back).unwrap(),
        std::fs::read(&stream).unwrap()
    );
}

/// `--permutation` maps each decoded vertex to the input file's own vertex
/// number, also for an OBJ whose faces use its vertices out of order
/// (decoded vertex i sits where the file's vertex `permutation[i]` does).
#[test]
fn the_permutation_indexes_the_input_files_vertices() {
    let input = temp(
        "out-of-order.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 4 2 3\nf 4 3 1\nf 4 1 2\nf 1 3 2\n",
    );
    let file_positions = obj_positions(&input);
    let stream = input.with_file_name("out-of-order.sps");
    let permutation = input.with_file_name("out-of-order.perm");
    let decoded = input.with_file_name("out-of-order-decoded.obj");
    succeeded(&splitstream(&[
        "encode",
        input.to_str().unwrap(),
        "-o",
        stream.to_str().unwrap(),
        "--permutation",
        permutation.to_str().unwrap(),
    ]));
    succeeded(&splitstream(&[
        "decode",
        stream.to_str().unwrap(),
        "-o",
        decoded.to_str().unwrap(),
    ]));
    let ids: Vec<usize> = std::fs::read_to_string(&permutation)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    let decoded_positions = obj_positions(&decoded);
    assert_eq!(ids.len(), file_positions.len());
    for (i, &id) in ids.iter().enumerate() {
        assert_eq!(
            decoded_positions[i], file_positions[id],
            "decoded vertex {i}"
        );
    }
}

/// `--tables static` writes no adaptive table (format 3.9), the default
/// writes some on a small raster, `info` counts them, and both streams
/// decode to the same mesh.
#[test]
fn tables_adaptive_and_static_decode_alike_and_info_counts_them() {
    let (input, adaptive) = encoded_raster("tables-adaptive.sps");
    let fixed = input.with_file_name("tables-static.sps");
    let (i, a, f) = (
        input.to_str().unwrap(),
        adaptive.to_str().unwrap(),
        fixed.to_str().unwrap(),
    );
    succeeded(&splitstream(&["encode", i, "-o", f, "--tables", "static"]));
    let tables = |p: &str| {
        let doc: serde_json::Value =
            serde_json::from_str(&succeeded(&splitstream(&["info", p, "--json"]))).unwrap();
        (
            doc["rans_tables_adaptive"].as_u64().unwrap(),
            doc["rans_tables"].as_u64().unwrap(),
        )
    };
    let (some, all) = tables(a);
    assert!(some > 0 && some <= all, "{some} of {all}");
    assert_eq!(tables(f).0, 0);
    assert!(
        succeeded(&splitstream(&["info", a]))
            .contains(&format!("rANS tables: {some} of {all} adaptive"))
    );
    let (a, f) = (
        std::fs::read(&adaptive).unwrap(),
        std::fs::read(&fixed).unwrap(),
    );
    assert!(a.len() <= f.len());
    let (da, df) = (
        splitstream_decoder_core::owned::decode_all(&a, false).unwrap(),
        splitstream_decoder_core::owned::decode_all(&f, false).unwrap(),
    );
    assert_eq!((da.positions, da.triangles), (df.positions, df.triangles));
}

/// Found by an audit of the command line (2026-12-08): `encode mine.ply -o
/// mine.ply` replaced the mesh with the stream (exit 0), a missing output
/// folder failed only after the whole encoding, a one-value `--rans-chunk`
/// took armadillo's encoding to 2.2 GB, `bench --terrain-side 100000000`
/// aborted on a failed allocation, and `--z-scale nan` was blamed on the
/// file's first vertex. Each is now one line before any work, and the
/// input is untouched.
#[test]
fn outputs_and_options_that_would_lose_data_or_run_away_are_refused_first() {
    let input = raster();
    let s = input.to_str().unwrap();
    let before = std::fs::read(&input).unwrap();
    let mesh_out = input.with_extension("ply");
    let out = input.with_file_name("refused.sps");
    let o = out.to_str().unwrap();
    std::fs::write(&mesh_out, b"not a stream").unwrap();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["encode", s, "-o", s],
            format!("{s}: a stream would be written under a mesh or grid file's extension (.asc)"),
        ),
        (
            vec!["encode", s, "-o", mesh_out.to_str().unwrap()],
            "name it .sps".to_string(),
        ),
        (
            vec!["encode", s, "-o", "/nonexistent-folder/x.sps"],
            "the folder /nonexistent-folder does not exist".to_string(),
        ),
        (
            vec!["encode", s, "-o", o, "--rans-chunk", "16"],
            "--rans-chunk 16 is below 256 values".to_string(),
        ),
        (
            vec!["encode", s, "-o", o, "--z-scale", "nan"],
            "--z-scale NaN must be finite and non-zero".to_string(),
        ),
        (
            vec!["bench", "--terrain-side", "100000000"],
            "--terrain-side 100000000 is outside 2..=4096".to_string(),
        ),
        (
            vec!["demo", "-o", "demo.glb"],
            "demo.glb: a stream would be written under a mesh or grid file's extension (.glb)"
                .to_string(),
        ),
    ];
    for (args, expected) in cases {
        let err = one_line_error(&splitstream(&args));
        assert!(err.contains(&expected), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read(&input).unwrap(), before);
    assert_eq!(std::fs::read(&mesh_out).unwrap(), b"not a stream");
    assert!(!out.exists(), "a refused encoding wrote {}", out.display());
}

/// Two files glued together verified as one, silently (an audit,
/// 2026-12-08): the bytes after the last level (SPEC §4.2) are now said.
#[test]
fn verify_says_bytes_after_the_last_level() {
    let input = raster();
    let out = input.with_file_name("glued.sps");
    let o = out.to_str().unwrap();
    succeeded(&splitstream(&["encode", input.to_str().unwrap(), "-o", o]));
    let clean = succeeded(&splitstream(&["verify", o]));
    assert!(!clean.contains("note:"), "{clean}");
    let mut bytes = std::fs::read(&out).unwrap();
    let end = bytes.len();
    bytes.extend_from_slice(b"14 extra bytes");
    std::fs::write(&out, &bytes).unwrap();
    let glued = succeeded(&splitstream(&["verify", o]));
    assert!(
        glued.contains(&format!(
            "note: 14 bytes after the last level's end (byte {end}) are not part of the stream"
        )),
        "{glued}"
    );
}
