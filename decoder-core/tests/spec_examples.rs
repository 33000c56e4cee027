//! Numbers quoted in SPEC.md (Appendix A, §2, §8, §9), recomputed.

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{
    DeficitContexts, Fnv1a, PlanePolicy, PositionMode, WingPolicy, crc32,
};

fn params() -> StreamParams {
    StreamParams {
        bits: 8,
        codec: ChunkCodec::Stored,
        chunk_limit: 4,
        rans_chunk_limit: 4,
        // Appendix A shows the fixed framing's bytes.
        framing: splitstream_decoder_core::Framing::Fixed,
        ..StreamParams::default()
    }
}

fn tetra_stream() -> Vec<u8> {
    tetra_stream_framed(splitstream_decoder_core::Framing::Fixed)
}

fn tetra_stream_framed(framing: splitstream_decoder_core::Framing) -> Vec<u8> {
    let positions = [[0i32, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]];
    let triangles = [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let deficits = [0u8, LEAF, LEAF, LEAF];
    let mut b = vec![SubstreamWriter::default(); 3];
    let mut prev = [0i32; 3];
    for p in positions {
        for k in 0..3 {
            b[0].signed(p[k] - prev[k]);
        }
        prev = p;
    }
    for t in triangles {
        for v in t {
            b[1].varint(v);
        }
    }
    for d in deficits {
        b[2].byte(d);
    }
    let base = LevelPayload {
        round_splits: vec![],
        plane: PlanePolicy::Off,
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: b,
        vertex_count: 4,
        triangle_count: 4,
        geometric_error: 1.0,
    };
    let mut s = vec![SubstreamWriter::default(); 7];
    s[0].bit(true); // flags
    s[1].byte(0); // o' = 0
    s[2].byte(1); // d' = 1
    s[3].byte(0); // P is a leaf
    s[4].byte(0); // C is a leaf
    // The dominant axis is x (n = (-100, 0, -100)): y, z, then x.
    for x in [1, 0, 0] {
        s[5].signed(x); // s' for P̂ = (0, -1, 0): P = (0, 0, 0)
    }
    for x in [0, 2, 4] {
        s[6].signed(x); // t' for Ĉ = (0, 2, 0): C = (2, 2, 2)
    }
    let l1 = LevelPayload {
        round_splits: vec![1],
        plane: PlanePolicy::Dominant,
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: s,
        vertex_count: 5,
        triangle_count: 6,
        geometric_error: 0.0,
    };
    write_stream(
        &StreamParams {
            framing,
            ..params()
        },
        &[base, l1],
    )
}

fn hex(bytes: &[u8]) -> String {
    let mut out = String::new();
    for (i, row) in bytes.chunks(16).enumerate() {
        out += &format!("{:04x}:", i * 16);
        for b in row {
            out += &format!(" {b:02x}");
        }
        out += "\n";
    }
    out
}

const SPEC: &str = include_str!("../SPEC.md");

/// Appendix A's compact framing (formats 3.11 and 3.12): the header's
/// flags, version and `table_len`, and the compact table's bytes, as
/// quoted; the stream decodes to the fixed one's hashes.
#[test]
fn appendix_a_tetrahedron_compact() {
    use splitstream_decoder_core::{Framing, Header};
    let stream = tetra_stream_framed(Framing::Compact);
    let header = Header::parse(&stream).unwrap();
    let head = header.head_len();
    if std::env::var("DUMP").is_ok() {
        println!("{} bytes, head_len {head}", stream.len());
        println!("{}", hex(&stream[..head]));
    }
    assert_eq!(&stream[8..12], &[3, 12, 0x0c, 0]);
    assert_eq!(header.table_len, 20);
    assert_eq!(&stream[28..32], &[20, 0, 0, 0]);
    let table = stream[96..head]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ");
    assert!(SPEC.contains(&format!("`{table}`")), "{table}");
    assert!(SPEC.contains(&format!("{} bytes in all", stream.len())));
    let fixed = decode_all(&tetra_stream(), true).unwrap();
    let compact = decode_all(&stream, true).unwrap();
    assert_eq!(fixed.round_hashes, compact.round_hashes);
}

#[test]
fn appendix_a_tetrahedron() {
    let stream = tetra_stream();
    assert_eq!(stream.len(), 471);
    if std::env::var("DUMP").is_ok() {
        let mesh = decode_all(&stream, true).unwrap();
        println!(
            "{:?} {:x?} {:?}",
            mesh.positions, mesh.round_hashes, mesh.triangles
        );
        println!("{}", hex(&stream));
    }
    // The complete hex dump of Appendix A is the stream, byte for byte.
    assert!(
        SPEC.contains(&hex(&stream)),
        "SPEC.md hex dump differs:\n{}",
        hex(&stream)
    );
    let mesh = decode_all(&stream, true).unwrap();
    assert_eq!(
        mesh.round_hashes,
        vec![0xe89ae8021be834dc, 0x500f34e8694c8efd]
    );
    for h in &mesh.round_hashes {
        assert!(SPEC.contains(&format!("`{h:016x}`")));
    }
    assert_eq!(
        mesh.triangles,
        vec![
            [4, 2, 1],
            [0, 1, 3],
            [4, 3, 2],
            [1, 2, 3],
            [0, 4, 1],
            [4, 0, 3]
        ]
    );
    assert_eq!(mesh.positions[0], [0, 0, 0]);
    assert_eq!(mesh.positions[4], [2, 2, 2]);
    // The level headers of Appendix A: level 0's plane policy 0, level 1's 1.
    assert_eq!(&stream[0xac..0xb0], &[0, 0, 0, 0]);
    assert_eq!(&stream[0x150..0x154], &[1, 0, 0, 0]);
    // §9: workspace_bytes of the example.
    assert_eq!(
        u64::from_le_bytes(stream[80..88].try_into().unwrap()),
        13296
    );
    // Corner references take 3 bytes here (3T = 18 fits in 24 bits).
    let layout = splitstream_decoder_core::Layout::new(5, 6, 4, 4, 4);
    assert_eq!(layout.corner_ref_width, 3);
    assert_eq!(layout.total, 64 + 72 + 120 + 16 + 8 + 24 + 7 * 1856);
}

#[test]
fn section_2_and_8_constants() {
    assert_eq!(crc32(b"123456789"), 0xCBF43926);
    let mut h = Fnv1a::default();
    assert_eq!(h.finish(), 0xcbf29ce484222325);
    h.bytes(b"a");
    assert_eq!(h.finish(), 0xaf63dc4c8601ec8c);
    assert_eq!(splitstream_decoder_core::limits::MAX_TRIANGLES, 0x5555_5554);
    assert_eq!(splitstream_decoder_core::limits::MAX_VERTICES, 0xFFFF_FFFE);
}

#[test]
fn section_10_3_minor_versions_and_trailing_bytes() {
    let stream = tetra_stream();
    // Any minor version of major 3 decodes as 3.0 (§1).
    let mut m = stream.clone();
    m[9] = 7;
    let crc = crc32(&m[..92]);
    m[92..96].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(decode_all(&m, false).unwrap().levels, 2);
    // Bytes past the end of the last level are ignored (§4.2, §10.3).
    let mut t = stream.clone();
    t.extend_from_slice(&[0xAB; 5]);
    assert_eq!(decode_all(&t, false).unwrap().levels, 2);
    // Header order (§3.3).
    assert_eq!(
        decode_all(&stream[..7], false).unwrap_err().class(),
        "truncated"
    );
    let mut bad = stream[..8].to_vec();
    bad[1] = b'X';
    assert_eq!(decode_all(&bad, false).unwrap_err().class(), "bad-magic");
    assert_eq!(
        decode_all(&stream[..9], false).unwrap_err().class(),
        "truncated"
    );
    let mut v2 = stream[..10].to_vec();
    v2[8] = 2;
    assert_eq!(
        decode_all(&v2, false).unwrap_err().class(),
        "unsupported-version"
    );
    // Truncated inside level 1: level 0 is decoded first.
    assert_eq!(
        decode_all(&stream[..400], false).unwrap_err().class(),
        "truncated"
    );
}

#[test]
fn section_5_2_deflate_must_be_exact() {
    use splitstream_decoder_core::Inflater;
    let raw = b"hello hello hello hello hello hello".to_vec();
    let packed = miniz_oxide::deflate::compress_to_vec(&raw, 9);
    let mut inf = Inflater::new();
    let mut out = vec![0u8; raw.len()];
    assert!(inf.inflate_exact(&packed, &mut out).is_ok());
    assert_eq!(out, raw);
    let mut extra = packed.clone();
    extra.push(0);
    assert!(inf.inflate_exact(&extra, &mut out).is_err());
    assert!(inf.inflate_exact(&packed, &mut out[1..]).is_err());
    let mut long = vec![0u8; raw.len() + 1];
    assert!(inf.inflate_exact(&packed, &mut long).is_err());
    let zlib = miniz_oxide::deflate::compress_to_vec_zlib(&raw, 9);
    assert!(inf.inflate_exact(&zlib, &mut out).is_err());
    // A stored deflate block: BFINAL=1, BTYPE=00, LEN=3, NLEN=!3, "abc".
    let mut three = [0u8; 3];
    assert!(
        inf.inflate_exact(&[0x01, 3, 0, 0xfc, 0xff, b'a', b'b', b'c'], &mut three)
            .is_ok()
    );
    assert_eq!(&three, b"abc");
    // The same block without BFINAL is not a complete stream.
    assert!(
        inf.inflate_exact(&[0x00, 3, 0, 0xfc, 0xff, b'a', b'b', b'c'], &mut three)
            .is_err()
    );
}

// ---------------------------------------------------------------------------
// The mathematical definitions of SPEC §7.1 and §7.5, written directly over a
// triangle list, checked against the reference decoder on random refinements.

use splitstream_decoder_core::{
    Error, Layout, MeshState, RecordSource, Ring, SplitRecord, limits::NONE,
};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// SPEC §7.1 from the triangle list alone.
fn spec_ring(tris: &[[u32; 3]], r: u32) -> Vec<u32> {
    let mut succ = std::collections::BTreeMap::new();
    for t in tris {
        for i in 0..3 {
            if t[i] == r {
                succ.insert(t[(i + 1) % 3], t[(i + 2) % 3]);
            }
        }
    }
    let targets: std::collections::BTreeSet<u32> = succ.values().copied().collect();
    let first = succ.keys().copied().find(|u| !targets.contains(u));
    match first {
        Some(u1) => {
            let mut ring = vec![NONE, u1];
            let mut u = u1;
            while let Some(&w) = succ.get(&u) {
                ring.push(w);
                u = w;
            }
            assert_eq!(ring.len(), succ.len() + 2);
            ring
        }
        None => {
            let start = *succ.keys().next().unwrap();
            let mut ring = vec![start];
            let mut u = succ[&start];
            while u != start {
                ring.push(u);
                u = succ[&u];
            }
            assert_eq!(ring.len(), succ.len(), "one closed fan");
            ring
        }
    }
}

fn spec_valence(tris: &[[u32; 3]], v: u32) -> usize {
    spec_ring(tris, v).len()
}

/// SPEC §7.5 over a plain triangle list.
fn spec_apply(
    tris: &mut Vec<[u32; 3]>,
    deficits: &mut Vec<u8>,
    r: u32,
    ring: &[u32],
    rec: &SplitRecord,
    c: u32,
) {
    let k = ring.len();
    let (o, d) = (rec.wing_offset as usize, rec.wing_distance as usize);
    let (a, b) = (ring[o], ring[o + d]);
    for w in [a, b] {
        if w != NONE && deficits[w as usize] != LEAF {
            deficits[w as usize] -= 1;
        }
    }
    // P (index r) owns arc 1, C arc 2 (wedges o+d .. o+k-1).
    let (x, y) = (r, c);
    let (start, len) = (o + d, k - d);
    for j in 0..len {
        let i = (start + j) % k;
        let (u, w) = (ring[i], ring[(i + 1) % k]);
        if u == NONE || w == NONE {
            continue;
        }
        let t = tris
            .iter_mut()
            .find(|t| (0..3).any(|s| t[s] == r && t[(s + 1) % 3] == u && t[(s + 2) % 3] == w))
            .expect("wedge is a triangle");
        for corner in t.iter_mut() {
            if *corner == r {
                *corner = c;
            }
        }
    }
    if a != NONE {
        tris.push([x, y, a]);
    }
    if b != NONE {
        tris.push([y, x, b]);
    }
    deficits[r as usize] = rec.deficit_p;
    deficits.push(rec.deficit_c);
}

struct Shadow {
    rng: Rng,
    flagged: Vec<u32>,
    tris: Vec<[u32; 3]>,
    deficits: Vec<u8>,
    next_c: u32,
    checked_rings: usize,
}

impl RecordSource for Shadow {
    fn flag(&mut self, _state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        Ok(self.flagged.contains(&v))
    }
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let mine = spec_ring(&self.tris, r);
        assert_eq!(ring.vertices(), &mine[..], "ring of {r}");
        self.checked_rings += 1;
        let k = mine.len();
        let ok: Vec<usize> = (0..k)
            .filter(|&i| mine[i] == NONE || self.deficits[mine[i] as usize] != 0)
            .collect();
        assert!(ok.len() >= 2, "test chose a bad round");
        let i = ok[self.rng.below(ok.len())];
        let mut j = i;
        while j == i {
            j = ok[self.rng.below(ok.len())];
        }
        let (lo, hi) = (i.min(j), i.max(j));
        let d = hi - lo;
        let (lp, lc) = (d, k - d);
        let pick = |rng: &mut Rng, val: usize| -> u8 {
            match rng.below(5) {
                0 => LEAF,
                n => ((n - 1) as u8).min((255 - val) as u8),
            }
        };
        let rec = SplitRecord {
            wing_offset: lo as u8,
            wing_distance: d as u8,
            deficit_p: pick(&mut self.rng, lp + 2),
            deficit_c: pick(&mut self.rng, lc + 2),
            position_p: state.positions()[r as usize],
            position_c: [1, 1, 1],
        };
        let c = self.next_c;
        self.next_c += 1;
        spec_apply(&mut self.tris, &mut self.deficits, r, &mine, &rec, c);
        Ok(rec)
    }
}

fn grid(n: u32) -> Vec<[u32; 3]> {
    let mut t = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let v = i * n + j;
            t.push([v, v + 1, v + n + 1]);
            t.push([v, v + n + 1, v + n]);
        }
    }
    t
}

fn octahedron() -> Vec<[u32; 3]> {
    splitstream_decoder_core::handmade::OCTA_TRIANGLES.to_vec()
}

fn run_random(base: Vec<[u32; 3]>, seed: u64) -> usize {
    let v0 = base.iter().flatten().copied().max().unwrap() + 1;
    let t0 = base.len() as u32;
    let (vcap, tcap) = (v0 + 400, t0 + 800);
    let layout = Layout::new(vcap, tcap, v0, t0, 16);
    let mut words = vec![0u64; layout.total as usize / 8 + 1];
    let buf: &mut [u8] = bytemuck::cast_slice_mut(&mut words);
    let (memory, _slots) = layout.carve(buf).unwrap();
    let mut state = MeshState::new(memory, 8, splitstream_decoder_core::Schedule::SplitValences);
    let mut rng = Rng(seed);
    let mut deficits = Vec::new();
    {
        let (p, c, d) = state.base_arrays();
        for v in 0..v0 as usize {
            p[v] = [0, 0, 0];
            d[v] = [0, 1, 2, LEAF][rng.below(4)];
            deficits.push(d[v]);
        }
        for (t, tri) in base.iter().enumerate() {
            c[3 * t..3 * t + 3].copy_from_slice(tri);
        }
    }
    state.finish_base(v0, t0).unwrap();
    let mut shadow = Shadow {
        rng,
        flagged: vec![],
        tris: base,
        deficits,
        next_c: v0,
        checked_rings: 0,
    };
    let mut ring = Ring::default();
    for _round in 0..40 {
        let n = state.vertex_count();
        // Independent random subset of the candidates whose split is possible.
        let mut flagged: Vec<u32> = Vec::new();
        for v in 0..n {
            if shadow.deficits[v as usize] != 0 || shadow.rng.below(3) == 0 {
                continue;
            }
            let ring_v = spec_ring(&shadow.tris, v);
            if ring_v.iter().any(|x| flagged.contains(x)) {
                continue;
            }
            let ok = ring_v
                .iter()
                .filter(|&&x| x == NONE || shadow.deficits[x as usize] != 0)
                .count();
            // Wings must not be pending candidates: keep it simple and
            // require every non-ghost neighbour to be non-candidate too.
            if ok < 2
                || ring_v
                    .iter()
                    .any(|&x| x != NONE && shadow.deficits[x as usize] == 0)
            {
                continue;
            }
            flagged.push(v);
        }
        if flagged.is_empty() {
            break;
        }
        let declared = flagged.len() as u32;
        if state.vertex_count() + declared > vcap || state.triangle_count() + 2 * declared > tcap {
            break;
        }
        shadow.flagged = flagged;
        state.run_round(declared, &mut shadow, &mut ring).unwrap();
        assert_eq!(state.triangles(), &shadow.tris[..]);
        assert_eq!(state.deficits(), &shadow.deficits[..]);
        // Valid state: directed edges unique, one fan per vertex, invariant.
        let mut edges: Vec<(u32, u32)> = shadow
            .tris
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .collect();
        edges.sort_unstable();
        assert!(edges.windows(2).all(|w| w[0] != w[1]));
        for v in 0..state.vertex_count() {
            let val = spec_valence(&shadow.tris, v);
            let d = shadow.deficits[v as usize];
            assert!(d == LEAF || val + d as usize <= 255);
        }
    }
    shadow.checked_rings
}

#[test]
fn spec_ring_and_split_match_the_reference() {
    let mut rings = 0;
    for seed in 1..600u64 {
        rings += run_random(grid(7), seed * 7919);
        rings += run_random(octahedron(), seed * 104729);
    }
    println!("rings checked: {rings}");
    assert!(rings > 1000);
}

/// §5.4: varints are at most 5 bytes, at most 32 bits, and minimal.
#[test]
fn section_5_4_varints() {
    let decode_base_triangle = |tri_bytes: &[u8]| {
        let mut b = vec![SubstreamWriter::default(); 3];
        for p in [[0i32, 0, 0], [1, 0, 0], [-1, 1, 0]] {
            for delta in p {
                b[0].signed(delta);
            }
        }
        for &x in tri_bytes {
            b[1].byte(x);
        }
        for _ in 0..3 {
            b[2].byte(LEAF);
        }
        let base = LevelPayload {
            round_splits: vec![],
            plane: PlanePolicy::Off,
            wings: WingPolicy::Ranks,
            deficits: DeficitContexts::Plain,
            records: splitstream_decoder_core::RecordOrder::WingsFirst,
            ties: splitstream_decoder_core::Ties::Ring,
            substreams: b,
            vertex_count: 3,
            triangle_count: 1,
            geometric_error: 0.0,
        };
        decode_all(&write_stream(&params(), &[base]), false)
            .map(|m| m.triangles)
            .map_err(|e| e.class())
    };
    assert_eq!(decode_base_triangle(&[0, 1, 2]), Ok(vec![[0, 1, 2]]));
    // Not minimal: a multi-byte varint ending in 0x00.
    assert_eq!(decode_base_triangle(&[0x80, 0x00, 1, 2]), Err("malformed"));
    assert_eq!(decode_base_triangle(&[0x81, 0x00, 1, 2]), Err("malformed"));
    // 0xFFFFFFFF is a valid varint (then an index out of range).
    assert_eq!(
        decode_base_triangle(&[0xff, 0xff, 0xff, 0xff, 0x0f, 1, 2]),
        Err("non-manifold")
    );
    // Over 32 bits, or over 5 bytes.
    assert_eq!(
        decode_base_triangle(&[0xff, 0xff, 0xff, 0xff, 0x10, 1, 2]),
        Err("malformed")
    );
    assert_eq!(
        decode_base_triangle(&[0x80, 0x80, 0x80, 0x80, 0x80, 0x00, 1, 2]),
        Err("malformed")
    );
}

/// The intermediate numbers of Appendix A's record (§7.4), from the public
/// prediction functions.
#[test]
fn appendix_a_predictions() {
    use splitstream_decoder_core::{
        ArcMeans, Plane, PlanePolicy, Target, arc_means, predict, predict::normal,
    };
    let layout = Layout::new(5, 6, 4, 4, 4);
    let mut words = vec![0u64; layout.total as usize / 8 + 1];
    let buf: &mut [u8] = bytemuck::cast_slice_mut(&mut words);
    let (memory, _slots) = layout.carve(buf).unwrap();
    let mut state = MeshState::new(memory, 8, splitstream_decoder_core::Schedule::SplitValences);
    {
        let (p, c, d) = state.base_arrays();
        p[..4].copy_from_slice(&[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]]);
        c[..12].copy_from_slice(&[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        d[..4].copy_from_slice(&[0, LEAF, LEAF, LEAF]);
    }
    state.finish_base(4, 4).unwrap();
    let mut ring = Ring::default();
    state.ring(0, &mut ring).unwrap();
    assert_eq!(ring.vertices(), &[1, 3, 2]);
    let eligible = state.wing_candidates(&ring);
    assert_eq!(eligible.count(), 3);
    assert_eq!(eligible.wings(0, 1), Ok((0, 1)));
    let m = arc_means(state.positions(), [0, 0, 0], &ring, 0, 1);
    assert_eq!(
        m,
        ArcMeans {
            wings: [5, 0, 5],
            arc_1: [0, 0, 0],
            arc_2: [0, 10, 0],
            sum: [10, 10, 10],
            count: 3,
            wing_edge: Some([-10, 0, 10]),
        }
    );
    assert_eq!(predict(&m, PositionMode::Optimal, Target::P), [0, -1, 0]);
    assert_eq!(predict(&m, PositionMode::Optimal, Target::C), [0, 2, 0]);
    assert_eq!(normal(&m), [-100, 0, -100]);
    let plane = Plane::new(PlanePolicy::Dominant, &m);
    assert_eq!(plane.axis, Some(0));
    assert_eq!(plane.order(), [1, 2, 0]);
    assert_eq!(plane.order().map(|a| plane.context(a)), [0, 0, 1]);
    assert_eq!(plane.decode([0, 1, 0]), [0, 1, 0]);
    assert_eq!(plane.decode([4, 0, 2]), [2, 0, 2]);
}

/// §5.2 (format 3.4): `max_chunk_len` bounds stored and deflate chunks, not
/// rANS chunks. The hand-made split with 4-value rANS chunks decodes the
/// same with a header maximum of 1; with 4-byte stored chunks the same
/// header is `malformed`. (Both maxima are below RANS_SLOT_BYTES, so the
/// declared workspace of §9 is the same.)
#[test]
fn section_5_2_max_chunk_len_bounds_byte_codec_chunks_only() {
    use splitstream_decoder_core::handmade::tetra_stream;
    let with_max = |stream: &[u8], max: u32| {
        let mut s = stream.to_vec();
        s[24..28].copy_from_slice(&max.to_le_bytes());
        let crc = crc32(&s[..92]);
        s[92..96].copy_from_slice(&crc.to_le_bytes());
        s
    };
    let rans = tetra_stream(ChunkCodec::RansAlways { lanes: 2 });
    assert_eq!(u32::from_le_bytes(rans[24..28].try_into().unwrap()), 4);
    let expected = decode_all(&rans, true).unwrap().round_hashes;
    assert_eq!(
        decode_all(&with_max(&rans, 1), true).unwrap().round_hashes,
        expected
    );
    let stored = tetra_stream(ChunkCodec::Stored);
    assert!(decode_all(&with_max(&stored, 4), false).is_ok());
    assert_eq!(
        decode_all(&with_max(&stored, 3), false)
            .unwrap_err()
            .class(),
        "malformed"
    );
}

/// §5.1 (3.5): level 0's header may not declare more seed triangles than
/// level 0's table entry holds, and a decoder holding level 0 alone (§9)
/// reports the same class as one holding the whole stream (§10.3). The
/// stream: the tetrahedron of Appendix A as the seed (4 triangles) and its
/// split as level 0's round, level 0's entry claiming 3 triangles, and a
/// level 1 whose counts keep the level table valid. Before 3.5 the whole
/// stream's decoder met a split past T_0 (`count-mismatch`) while one sized
/// for level 0 could not hold the seed (`capacity-exceeded`).
#[test]
fn section_5_1_seed_triangles_at_most_level_0s() {
    use splitstream_decoder_core::owned::OwnedWorkspace;
    use splitstream_decoder_core::writer::{SeedPayload, write_stream_seeded};
    use splitstream_decoder_core::{Header, LevelTable, layout_for};

    let seed = SeedPayload::new(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        &[0, LEAF, LEAF, LEAF],
    );
    let split = |vertex_count, triangle_count| {
        let mut s = vec![SubstreamWriter::default(); 7];
        s[0].bit(true);
        s[1].byte(0);
        s[2].byte(1);
        s[3].byte(0);
        s[4].byte(0);
        for x in [1, 0, 0] {
            s[5].signed(x);
        }
        for x in [0, 2, 4] {
            s[6].signed(x);
        }
        LevelPayload {
            round_splits: vec![1],
            plane: PlanePolicy::Dominant,
            wings: WingPolicy::Ranks,
            deficits: DeficitContexts::Plain,
            records: splitstream_decoder_core::RecordOrder::WingsFirst,
            ties: splitstream_decoder_core::Ties::Ring,
            substreams: s,
            vertex_count,
            triangle_count,
            geometric_error: 0.0,
        }
    };
    let stream_with =
        |t0: u32| write_stream_seeded(&params(), &seed, &[split(5, t0), split(6, t0 + 2)]);

    // The claim at its lowest legal value (the seed's 4 triangles) passes the
    // level header; the split then takes T past it (§7.5), as before 3.5.
    // Below the seed's count the level header fails: same class, and for
    // the decoder that holds level 0 alone, no longer capacity-exceeded.
    for (t0, what) in [(4, "a split past T_0"), (3, "the seed above T_0")] {
        let stream = stream_with(t0);
        let header = Header::parse(&stream).unwrap();
        let table = LevelTable::parse(&stream, &header).unwrap();
        let whole = decode_all(&stream, false).unwrap_err();
        assert_eq!(whole.class(), "count-mismatch", "{what}: {whole:?}");
        let level_0 = layout_for(&header, &table, 0).total.div_ceil(8) * 8;
        let mut ws = OwnedWorkspace::within(&stream, level_0).unwrap();
        let mut decoder = ws.decoder(&stream).unwrap();
        assert_eq!(decoder.levels_that_fit(), 1);
        let prefix = decoder.decode_available(&stream).unwrap_err();
        assert_eq!(prefix, whole, "{what}");
    }
}
