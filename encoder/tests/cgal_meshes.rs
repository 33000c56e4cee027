//! decode(encode(M)) == M on every mesh of CGAL's sample data (143 OFF, PLY
//! and STL files, fetched into encoder/data/real/cgal/ by
//! encoder/data/fetch.sh): closed and open surfaces, polygons, several
//! components, sharp features, a triangle alone. The files that break an
//! input rule must fail `check_mesh` with the rule named below, and encode
//! exactly once repaired. Without the folder this test says so and passes.

mod roundtrip_check;

use std::path::Path;

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::input::{MeshError, ReadOptions, check_mesh, read_mesh, repair_mesh};

/// The rule each broken file breaks first, as `check_mesh` reports it.
fn expected_error(file: &str) -> Option<fn(&MeshError) -> bool> {
    let orientation: fn(&MeshError) -> bool =
        |e| matches!(e, MeshError::InconsistentOrientation { .. });
    let unreferenced: fn(&MeshError) -> bool =
        |e| matches!(e, MeshError::UnreferencedVertex { .. });
    let nonmanifold_vertex: fn(&MeshError) -> bool =
        |e| matches!(e, MeshError::NonManifoldVertex { .. });
    match file {
        // Triangles listed with their corners in random order.
        "blobby-shuffled.off"
        | "cube-shuffled.off"
        | "cube4-shuffled.off"
        | "oblong-shuffled.off"
        | "tet-shuffled.off" => Some(orientation),
        // Vertices no face uses.
        "cube-ouvert.off" | "prim.off" => Some(unreferenced),
        // Surfaces touching at a vertex.
        "pig.stl" | "polygon_mesh.off" => Some(nonmanifold_vertex),
        // A point cloud: 22,300 vertices and no face.
        "b9.ply" => Some(|e| {
            matches!(
                e,
                MeshError::Empty {
                    vertices: 22_300,
                    triangles: 0
                }
            )
        }),
        _ => None,
    }
}

#[test]
fn every_cgal_sample_mesh_roundtrips_exactly() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real/cgal");
    if !dir.join(".complete").exists() {
        eprintln!("skipped data/real/cgal/: run encoder/data/fetch.sh");
        return;
    }
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|name| !name.starts_with('.'))
        .collect();
    files.sort();
    assert!(
        files.len() >= 140,
        "{} files in {}",
        files.len(),
        dir.display()
    );
    let (mut exact, mut repaired) = (0, 0);
    for file in &files {
        // roundtrip_real.rs encodes these three, in both position modes.
        if ["armadillo.off", "bunny00.off", "refined_elephant.off"].contains(&file.as_str()) {
            continue;
        }
        let mesh = read_mesh(&dir.join(file), &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let mesh = match (check_mesh(&mesh), expected_error(file)) {
            (Ok(_), None) => mesh,
            (Err(e), Some(expected)) => {
                assert!(expected(&e), "{file}: {e}");
                if matches!(e, MeshError::Empty { .. }) {
                    continue;
                }
                let (mesh, report) = repair_mesh(&mesh);
                check_mesh(&mesh).unwrap_or_else(|e| panic!("{file} repaired ({report}): {e}"));
                repaired += 1;
                mesh
            }
            (Ok(_), Some(_)) => panic!("{file}: passes the check it should fail"),
            (Err(e), None) => panic!("{file}: {e}"),
        };
        // The default (constrained mode, one rANS lane), and optimal mode
        // in three lanes.
        roundtrip_check::assert_roundtrip(&mesh, &EncodeOptions::default());
        let optimal = EncodeOptions {
            position_mode: PositionMode::Optimal,
            codec: ChunkCodec::Rans { lanes: 3 },
            ..EncodeOptions::default()
        };
        roundtrip_check::assert_roundtrip(&mesh, &optimal);
        exact += 1;
    }
    eprintln!("{exact} meshes exact in both modes, {repaired} of them repaired first");
    assert_eq!(repaired, 9);
}
