//! Splitting rectangles around samples whose error exceeds their T (see
//! the module docs of [`super`]).

use super::Rect;

/// Scratch of the refinement.
#[derive(Debug, Default)]
pub struct Scratch {
    /// Samples over their T, or border corners that could not be removed
    /// (sample indices; duplicates allowed).
    pub over: Vec<u32>,
    /// The live rectangle holding each cell.
    owner: Vec<u32>,
    /// Rectangles to split.
    marked: Vec<u32>,
}

impl Scratch {
    pub fn new(samples: usize, cells: usize) -> Self {
        Scratch {
            // A sample is reported by each triangle holding it (two at most
            // unless it is a vertex, and vertices are exact).
            over: Vec::with_capacity(2 * samples + 64),
            owner: Vec::with_capacity(cells),
            marked: Vec::with_capacity(cells),
        }
    }
}

/// Splits every rectangle touching a sample of `sc.over` in two halves
/// across its longer side (the quad-tree's merges undone, about). False
/// when none of them can be split (all single cells): nothing changed.
pub fn split_around(rows: usize, cols: usize, rects: &mut Vec<Rect>, sc: &mut Scratch) -> bool {
    let cw = cols - 1;
    sc.owner.clear();
    sc.owner.resize(cw * (rows - 1), u32::MAX);
    for (i, r) in rects.iter().enumerate().filter(|(_, r)| r.alive) {
        for y in r.row0..r.row1 {
            let row = y as usize * cw;
            sc.owner[row + r.col0 as usize..row + r.col1 as usize].fill(i as u32);
        }
    }
    sc.marked.clear();
    for &s in &sc.over {
        let (x, y) = (s as usize % cols, s as usize / cols);
        // The (up to four) cells that have this sample as a corner.
        for cy in y.saturating_sub(1)..=y.min(rows - 2) {
            for cx in x.saturating_sub(1)..=x.min(cols - 2) {
                sc.marked.push(sc.owner[cy * cw + cx]);
            }
        }
    }
    sc.marked.sort_unstable();
    sc.marked.dedup();
    let mut any = false;
    for &i in &sc.marked {
        let r = rects[i as usize];
        let (w, h) = (r.col1 - r.col0, r.row1 - r.row0);
        if w == 1 && h == 1 {
            continue;
        }
        let (a, b) = if w >= h {
            let mid = r.col0 + w / 2;
            (Rect { col1: mid, ..r }, Rect { col0: mid, ..r })
        } else {
            let mid = r.row0 + h / 2;
            (Rect { row1: mid, ..r }, Rect { row0: mid, ..r })
        };
        rects[i as usize] = a;
        rects.push(b);
        any = true;
    }
    any
}
