//! Numbers quoted in SPEC.md (Appendix A, §2, §8, §9), recomputed.

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{Fnv1a, PositionMode, crc32};

fn params() -> StreamParams {
    StreamParams {
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec: ChunkCodec::Stored,
        chunk_limit: 4,
    }
}

fn tetra_stream() -> Vec<u8> {
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
        substreams: b,
        vertex_count: 4,
        triangle_count: 4,
        geometric_error: 1.0,
    };
    let mut s = vec![SubstreamWriter::default(); 8];
    s[0].bit(true); // flags
    s[1].byte(0); // o
    s[2].byte(1); // d
    s[3].bit(false); // q
    s[4].byte(LEAF); // deficit P
    s[5].byte(LEAF); // deficit C
    for _ in 0..3 {
        s[6].signed(2); // e
        s[7].signed(-1); // m
    }
    let l1 = LevelPayload {
        round_splits: vec![1],
        substreams: s,
        vertex_count: 5,
        triangle_count: 6,
        geometric_error: 0.0,
    };
    write_stream(&params(), &[base, l1])
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

#[test]
fn print_tetra() {
    let stream = tetra_stream();
    println!("len {}", stream.len());
    println!("{}", hex(&stream));
    let mesh = decode_all(&stream, true).unwrap();
    for h in &mesh.round_hashes {
        println!("hash {h:016x}");
    }
    println!("{:?}", mesh.triangles);
}

fn recrc_header(s: &mut [u8]) {
    let c = crc32(&s[..92]);
    s[92..96].copy_from_slice(&c.to_le_bytes());
}

#[test]
fn explore() {
    assert_eq!(crc32(b"123456789"), 0xCBF43926);
    let _ = Fnv1a::default();
    let stream = tetra_stream();
    // trailing bytes
    let mut t = stream.clone();
    t.push(0);
    println!("trailing: {:?}", decode_all(&t, false).map(|m| m.levels));
    // minor 7
    let mut m = stream.clone();
    m[9] = 7;
    recrc_header(&mut m);
    println!("minor7: {:?}", decode_all(&m, false).map(|m| m.levels));
    // major 2
    let mut m = stream.clone();
    m[8] = 2;
    println!("major2: {:?}", decode_all(&m, false).map(|m| m.levels));
    // short
    println!("len9: {:?}", decode_all(&stream[..9], false).map(|m| m.levels));
    println!("len50: {:?}", decode_all(&stream[..50], false).map(|m| m.levels));
    // deflate tests
    use splitstream_decoder_core::Inflater;
    let _ = Inflater::new();
}

#[test]
fn explore_inflate() {
    use splitstream_decoder_core::Inflater;
    let raw = b"hello hello hello hello hello hello".to_vec();
    let packed = miniz_oxide::deflate::compress_to_vec(&raw, 9);
    let mut inf = Inflater::new();
    let mut out = vec![0u8; raw.len()];
    println!("exact {:?}", inf.inflate_exact(&packed, &mut out));
    let mut p2 = packed.clone(); p2.push(0);
    println!("trailing {:?}", inf.inflate_exact(&p2, &mut out));
    let mut short = vec![0u8; raw.len() - 1];
    println!("short out {:?}", inf.inflate_exact(&packed, &mut short));
    let mut long = vec![0u8; raw.len() + 1];
    println!("long out {:?}", inf.inflate_exact(&packed, &mut long));
    let z = miniz_oxide::deflate::compress_to_vec_zlib(&raw, 9);
    println!("zlib {:?}", inf.inflate_exact(&z, &mut out));
    println!("trunc {:?}", inf.inflate_exact(&packed[..packed.len()-1], &mut out));
    // stored block raw deflate: 01 len nlen data
    let mut st = vec![0x01, 3, 0, 0xfc, 0xff]; st.extend_from_slice(b"abc");
    let mut o3 = vec![0u8; 3];
    println!("stored block {:?} {:?}", inf.inflate_exact(&st, &mut o3), o3);
    // non-final block then nothing
    let mut nf = vec![0x00, 3, 0, 0xfc, 0xff]; nf.extend_from_slice(b"abc");
    println!("nonfinal {:?}", inf.inflate_exact(&nf, &mut o3));
}
