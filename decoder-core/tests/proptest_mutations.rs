//! Property tests: random byte mutations, truncations and bit flips of
//! valid streams (the hand-made ones of tests/handmade.rs and generated deep
//! ones) never panic and always give a typed error or a valid decode. Both
//! decoding paths run: the owned `decode_all` and the no-alloc `Decoder`
//! over an exactly sized workspace; they must agree.

/// Rewrites the header and level-table CRCs (fixed or compact table), so
/// mutations there reach the field checks (the chunk and level-header CRCs
/// still guard the levels).
#[path = "../fuzz/src/fix_checksums.rs"]
#[allow(dead_code)]
mod fix;
#[path = "../fuzz/src/mesh_check.rs"]
mod mesh_check;
#[path = "../fuzz/src/streams.rs"]
mod streams;

use std::sync::OnceLock;

use proptest::prelude::*;
use splitstream_decoder_core::Error;
use splitstream_decoder_core::owned::decode_all;

fn valid_streams() -> &'static Vec<Vec<u8>> {
    static S: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    S.get_or_init(|| {
        streams::seed_generated()
            .into_iter()
            .map(|g| g.stream)
            .collect()
    })
}

#[derive(Clone, Debug)]
enum Mutation {
    Set(usize, u8),
    Flip(usize, u8),
    Insert(usize, u8),
    Remove(usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(a, v)| Mutation::Set(a, v)),
        (any::<usize>(), 0u8..8).prop_map(|(a, b)| Mutation::Flip(a, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(a, v)| Mutation::Insert(a, v)),
        any::<usize>().prop_map(Mutation::Remove),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(stream: &mut Vec<u8>, m: &Mutation) {
    let n = stream.len().max(1);
    match *m {
        Mutation::Set(a, v) => {
            if let Some(b) = stream.get_mut(a % n) {
                *b = v;
            }
        }
        Mutation::Flip(a, bit) => {
            if let Some(b) = stream.get_mut(a % n) {
                *b ^= 1 << bit;
            }
        }
        Mutation::Insert(a, v) => stream.insert(a % (stream.len() + 1), v),
        Mutation::Remove(a) => {
            if !stream.is_empty() {
                stream.remove(a % stream.len());
            }
        }
        Mutation::Truncate(a) => stream.truncate(a % n),
    }
}

/// Decodes both ways; checks they agree and that a success is a manifold.
fn decode_both(stream: &[u8]) -> Result<(), TestCaseError> {
    let owned = decode_all(stream, true);
    let d = streams::decode_full(stream);
    streams::check_piped(stream, &d).map_err(TestCaseError::fail)?;
    match (&owned, d.error) {
        (Ok(mesh), None) => {
            prop_assert_eq!(&mesh.round_hashes, &d.hashes);
            prop_assert_eq!(&mesh.triangles, &d.triangles);
            mesh_check::check_oriented_manifold(mesh.positions.len(), &mesh.triangles)
                .map_err(TestCaseError::fail)?;
        }
        (Err(a), Some(b)) => {
            // The owned path refuses absurd workspaces (CapacityExceeded)
            // where the capped no-alloc path finds its buffer too small:
            // the same class.
            if *a == Error::CapacityExceeded && matches!(b, Error::WorkspaceTooSmall { .. }) {
                return Ok(());
            }
            prop_assert_eq!(*a, b);
            prop_assert!(!a.class().is_empty());
            prop_assert!(!a.to_string().is_empty());
        }
        // Only the owned path sizes its workspace without a cap.
        (Err(a), None) => return Err(TestCaseError::fail(format!("owned failed: {a:?}"))),
        (Ok(_), Some(b)) => {
            prop_assert!(matches!(b, Error::WorkspaceTooSmall { .. }), "{b:?}")
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn mutated_streams_never_panic(
        pick in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..6),
        fix_head in any::<bool>(),
    ) {
        let all = valid_streams();
        let mut s = all[pick % all.len()].clone();
        for m in &mutations {
            apply(&mut s, m);
        }
        if fix_head {
            fix::fix_head_checksums(&mut s);
        }
        decode_both(&s)?;
    }

    #[test]
    fn every_single_bit_flip_is_caught(pick in any::<usize>(), at in any::<usize>(), bit in 0u8..8) {
        let all = valid_streams();
        let mut s = all[pick % all.len()].clone();
        let at = at % s.len();
        s[at] ^= 1 << bit;
        // CRC-32 catches every single-bit error in its scope; the only bytes
        // outside every checksum are none (SPEC §3.3, §4.2, §5).
        let err = decode_all(&s, false).unwrap_err();
        prop_assert!(
            matches!(err.class(), "checksum-mismatch" | "bad-magic" | "unsupported-version" | "malformed" | "truncated"),
            "byte {} bit {}: {:?}", at, bit, err
        );
        decode_both(&s)?;
    }

    #[test]
    fn truncations_never_decode(pick in any::<usize>(), len in any::<usize>()) {
        let all = valid_streams();
        let s = &all[pick % all.len()];
        let len = len % s.len();
        prop_assert!(decode_all(&s[..len], false).is_err());
        decode_both(&s[..len])?;
    }
}

/// Exhaustive: every truncation of every seed stream.
#[test]
fn all_truncations_are_errors() {
    for s in valid_streams().iter().take(6) {
        for len in 0..s.len() {
            let e = decode_all(&s[..len], false).unwrap_err();
            assert!(!e.class().is_empty());
        }
    }
}

/// The head fix finds a compact table too (SPEC §4.3): a changed table byte
/// then reaches the table's field checks, not its checksum.
#[test]
fn head_fix_reaches_every_framings_table() {
    let mut framings = std::collections::BTreeSet::new();
    for s in valid_streams() {
        let mut fixed = s.clone();
        let table_end = fix::fix_head_checksums(&mut fixed).expect("a valid stream has its head");
        assert_eq!(&fixed, s, "a valid stream's checksums are already right");
        framings.insert(s[10] & 12);
        for at in 96..table_end {
            let mut m = s.clone();
            m[at] ^= 0x40;
            fix::fix_head_checksums(&mut m);
            let e = decode_all(&m, false).err();
            assert!(
                !matches!(
                    e,
                    Some(Error::ChecksumMismatch(
                        splitstream_decoder_core::ChecksumScope::LevelTable
                    ))
                ),
                "table byte {at} of framing {:#x}: {e:?}",
                s[10] & 12
            );
        }
    }
    // Fixed (0), compact level headers (4) and compact table (12).
    assert_eq!(framings.into_iter().collect::<Vec<_>>(), [0, 4, 12]);
}
