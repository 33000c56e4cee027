//! `splitstream grid`: the client-side grid-tile simplifier from the
//! command line.

mod cli;

use std::path::PathBuf;

use cli::{one_line_error, splitstream};

fn temp(name: &str, contents: &str) -> PathBuf {
    cli::temp("grid-cli", name, contents)
}

fn asc(rows: usize, cols: usize, z: impl Fn(usize, usize) -> String) -> String {
    let mut s = format!(
        "ncols {cols}\nnrows {rows}\nxllcorner 0\nyllcorner 0\ncellsize 30\nNODATA_value -9999\n"
    );
    for r in 0..rows {
        let line: Vec<String> = (0..cols).map(|c| z(r, c)).collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    s
}

#[test]
fn tilted_plane_becomes_two_triangles() {
    let input = temp(
        "plane.asc",
        &asc(17, 17, |r, c| {
            format!("{}", 100.0 + 2.0 * c as f64 + 0.5 * r as f64)
        }),
    );
    let output = input.with_file_name("plane.ply");
    let out = splitstream(&[
        "grid",
        input.to_str().unwrap(),
        "--height",
        "700",
        "-o",
        output.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("facets 256 -> 1"), "{stdout}");
    assert!(stdout.contains("triangles 512 -> 2"), "{stdout}");
    assert!(stdout.contains("max vertical error 0.0000"), "{stdout}");
    let ply = std::fs::read(&output).unwrap();
    let header = String::from_utf8_lossy(&ply[..ply.len().min(300)]);
    assert!(header.contains("element vertex 4"), "{header}");
    assert!(header.contains("element face 2"), "{header}");
}

#[test]
fn neighbour_resolution_is_accepted() {
    let input = temp(
        "hills.asc",
        &asc(17, 17, |r, c| {
            format!("{:.2}", 50.0 * ((r * c) as f64 / 40.0).sin())
        }),
    );
    let output = input.with_file_name("hills.ply");
    let out = splitstream(&[
        "grid",
        input.to_str().unwrap(),
        "--height",
        "700",
        "--neighbour-res",
        "60,-,30,120",
        "-o",
        output.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_arguments_give_one_line() {
    let input = temp("small.asc", &asc(5, 5, |_, _| "1".into()));
    let i = input.to_str().unwrap();
    let o = input.with_file_name("small.ply");
    let o = o.to_str().unwrap();
    let err = one_line_error(&splitstream(&["grid", i, "--height", "-5", "-o", o]));
    assert!(err.contains("--height"), "{err}");
    let err = one_line_error(&splitstream(&[
        "grid",
        i,
        "--height",
        "700",
        "--neighbour-res",
        "1,2",
        "-o",
        o,
    ]));
    assert!(err.contains("N,E,S,W"), "{err}");
    let err = one_line_error(&splitstream(&[
        "grid",
        i,
        "--height",
        "700",
        "--neighbour-res",
        "a,-,-,-",
        "-o",
        o,
    ]));
    assert!(err.contains("not a number"), "{err}");
    // 30 m tile, 4 cells a side: a 90 m neighbour does not line up.
    let err = one_line_error(&splitstream(&[
        "grid",
        i,
        "--height",
        "700",
        "--neighbour-res",
        "90,-,-,-",
        "-o",
        o,
    ]));
    assert!(err.contains("North"), "{err}");
    let err = one_line_error(&splitstream(&["grid", i, "--height", "700"]));
    assert!(err.contains("-o"), "{err}");
    let err = one_line_error(&splitstream(&["grid", i, "--height", "700", "-o", "x.stl"]));
    assert!(err.contains(".ply"), "{err}");
    let err = one_line_error(&splitstream(&[
        "grid",
        "missing.asc",
        "--height",
        "700",
        "-o",
        o,
    ]));
    assert!(err.contains("missing.asc"), "{err}");
}

#[test]
fn garbage_grids_give_typed_errors() {
    let o = std::env::temp_dir().join("splitstream-grid-cli-garbage.ply");
    let o = o.to_str().unwrap();
    let holes = temp(
        "holes.asc",
        &asc(4, 4, |r, c| {
            if r == 1 && c == 2 {
                "-9999".into()
            } else {
                "3".into()
            }
        }),
    );
    let err = one_line_error(&splitstream(&[
        "grid",
        holes.to_str().unwrap(),
        "--height",
        "700",
        "-o",
        o,
    ]));
    assert!(err.contains("not finite"), "{err}");
    let tiny = temp("tiny.asc", &asc(1, 1, |_, _| "3".into()));
    let err = one_line_error(&splitstream(&[
        "grid",
        tiny.to_str().unwrap(),
        "--height",
        "700",
        "-o",
        o,
    ]));
    assert!(err.contains("2 x 2"), "{err}");
    let mesh = temp("mesh.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    let out = splitstream(&["grid", mesh.to_str().unwrap(), "--height", "700", "-o", o]);
    one_line_error(&out);
}

/// matplotlib's topobathy.npz lists latitudes that are not evenly spaced:
/// the tiles need one spacing, so the grid is refused with one line.
#[test]
fn unevenly_spaced_rows_are_refused() {
    let input = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/real/topobathy.npz");
    if !input.exists() {
        eprintln!("skipped topobathy.npz: run encoder/data/fetch.sh");
        return;
    }
    let output = std::env::temp_dir().join("grid-cli-topobathy.ply");
    let out = splitstream(&[
        "grid",
        input.to_str().unwrap(),
        "--height",
        "1000",
        "-o",
        output.to_str().unwrap(),
    ]);
    let message = one_line_error(&out);
    assert!(
        message.contains("not evenly spaced") && message.contains("regular grid"),
        "{message}"
    );
}
