//! The simplifier's working state: geometry, quadrics, connectivity and the
//! bookkeeping that keeps lazily deleted queue entries honest.

use super::BaselineOptions;
use super::queue::{Entry, Queue};
use crate::corner_table::{CornerTable, Fan, NONE, next, prev};
use crate::quadric::{Quadric, collapse_target, vertex_quadrics};

pub struct Simplifier<'o> {
    pub options: &'o BaselineOptions,
    pub table: CornerTable,
    pub positions: Vec<[f64; 3]>,
    pub quadrics: Vec<Quadric>,
    pub alive: Vec<bool>,
    pub on_boundary: Vec<bool>,
    /// Set when a collapse at this vertex was refused for topology or
    /// geometry; such edges are re-scored once a neighbouring collapse may
    /// have made them legal.
    pub refused: Vec<bool>,
    /// Scratch marks for set intersections; `mark[v] == token` means "in".
    pub mark: Vec<u32>,
    pub token: u32,
    pub heap: Queue,
    pub alive_count: usize,
    /// Reusable fans so the hot loop does not allocate.
    pub fans: [Fan; 3],
    pub neighbours: Vec<u32>,
}

impl<'o> Simplifier<'o> {
    pub fn new(
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        options: &'o BaselineOptions,
    ) -> Self {
        let n = positions.len();
        // The input checker rejects out-of-range indices; skip them here
        // rather than panic, as `vertex_quadrics` does.
        let valid = |t: &[u32; 3]| t.iter().all(|&v| (v as usize) < n);
        let owned: Vec<[u32; 3]>;
        let triangles = if triangles.iter().all(valid) {
            triangles
        } else {
            owned = triangles.iter().copied().filter(valid).collect();
            &owned
        };
        let table = CornerTable::new(n, triangles);
        let mut on_boundary = vec![false; n];
        for (c, &o) in table.opposite.iter().enumerate() {
            if o == NONE {
                let c = c as u32;
                on_boundary[table.v(next(c)) as usize] = true;
                on_boundary[table.v(prev(c)) as usize] = true;
            }
        }
        let alive: Vec<bool> = table.corner_of.iter().map(|&c| c != NONE).collect();
        let alive_count = alive.iter().filter(|&&a| a).count();
        Simplifier {
            options,
            quadrics: vertex_quadrics(positions, triangles, options.boundary_weight),
            positions: positions.to_vec(),
            table,
            alive,
            on_boundary,
            refused: vec![false; n],
            mark: vec![0; n],
            token: 0,
            heap: Queue::default(),
            alive_count,
            fans: Default::default(),
            neighbours: Vec::new(),
        }
    }

    /// Scores every edge once and heapifies in O(n).
    pub fn fill_queue(&mut self) {
        let mut entries = Vec::with_capacity(self.table.vertex.len() / 2 + 1);
        for c in 0..self.table.vertex.len() as u32 {
            let o = self.table.o(c);
            if o != NONE && o < c {
                continue; // the other side scores this edge
            }
            if let Some(e) = self.score(c) {
                entries.push(e);
            }
        }
        self.heap = Queue::from_entries(entries);
    }

    /// The edge facing live corner `c`, as (survivor, removed) vertices.
    pub fn edge(&self, c: u32) -> (u32, u32) {
        (self.table.v(next(c)), self.table.v(prev(c)))
    }

    /// Where edge `(u, v)` would collapse to and at what error; `None` when
    /// `lock_boundary` forbids it outright.
    pub fn target(&self, u: u32, v: u32) -> Option<([f64; 3], f64, Quadric)> {
        let (ui, vi) = (u as usize, v as usize);
        let q = self.quadrics[ui] + self.quadrics[vi];
        let (pu, pv) = (self.positions[ui], self.positions[vi]);
        if self.options.lock_boundary {
            // A boundary vertex may absorb an interior neighbour but never move.
            match (self.on_boundary[ui], self.on_boundary[vi]) {
                (true, true) => return None,
                (true, false) => return Some((pu, q.error(pu), q)),
                (false, true) => return Some((pv, q.error(pv), q)),
                (false, false) => {}
            }
        }
        let (p, e) = collapse_target(&q, pu, pv, self.options.constrained);
        Some((p, e, q))
    }

    /// The queue entry of the edge facing live corner `c`.
    fn score(&self, c: u32) -> Option<Entry> {
        let (u, v) = self.edge(c);
        let (_, error, _) = self.target(u, v)?;
        Some(Entry::new(error, c))
    }

    /// Queues every edge around `v` except the one to `skip`, once each.
    fn queue_edges_of(&mut self, v: u32, skip: u32) {
        let mut fan = std::mem::take(&mut self.fans[2]);
        self.table.fan(v, &mut fan);
        for &c in &fan.corners {
            // prev(c) faces the edge (v, vertex[next c]); together these
            // cover every edge but the one closing an open fan, which only
            // next(c) of the last triangle faces.
            let mut edges = [prev(c), NONE];
            if self.table.o(next(c)) == NONE {
                edges[1] = next(c);
            }
            for e in edges {
                if e == NONE {
                    continue;
                }
                let (x, y) = self.edge(e);
                if x == skip || y == skip {
                    continue;
                }
                if let Some(entry) = self.score(e) {
                    self.heap.push(entry);
                }
            }
        }
        self.fans[2] = fan;
    }

    /// A fresh mark token; old marks become meaningless without clearing.
    pub fn next_token(&mut self) -> u32 {
        self.token = self.token.wrapping_add(1);
        if self.token == 0 {
            self.mark.fill(0);
            self.token = 1;
        }
        self.token
    }

    /// The distinct neighbours of `v` into `self.neighbours`.
    pub fn collect_neighbours(&mut self, v: u32) {
        let mut fan = std::mem::take(&mut self.fans[2]);
        self.table.fan(v, &mut fan);
        let token = self.next_token();
        self.neighbours.clear();
        for &c in &fan.corners {
            for w in [self.table.v(next(c)), self.table.v(prev(c))] {
                if self.mark[w as usize] != token {
                    self.mark[w as usize] = token;
                    self.neighbours.push(w);
                }
            }
        }
        self.fans[2] = fan;
    }

    /// After a collapse into `a`: re-score every edge of `a`, and every edge
    /// of a neighbour that had a refused collapse, since the change around
    /// `a` may have made it legal.
    pub fn requeue_around(&mut self, a: u32) {
        self.refused[a as usize] = false;
        self.collect_neighbours(a);
        let retry: Vec<u32> = self
            .neighbours
            .iter()
            .copied()
            .filter(|&n| self.refused[n as usize])
            .collect();
        self.queue_edges_of(a, NONE);
        for n in retry {
            self.refused[n as usize] = false;
            self.queue_edges_of(n, a);
        }
    }
}
