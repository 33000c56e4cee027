#!/usr/bin/env python3
"""Positions before wings on raster terrain: what a record would cost if a
split's new position were read first, as a rank among the free lattice
points of the split vertex's fan, and its wings then as ranks among the
ring entries that keep every new triangle the right way up in x and y. The
measurement behind encoder/BENCHMARKS.md, "Positions before wings on
rasters".

    python3 decoder-core/examples/positions_first.py STREAM.sps [CAP]

STREAM is a constrained stream of a raster whose x and y the encoder kept
on the raster's own lattice (`splitstream encode DEM --geographic`,
`splitstream demo`): a terrain is the graph of a function of x and y, so
in the xy projection a split vertex's fan is a star of triangles that no
other vertex lies in, and a split's new vertex lies in it on a free lattice
point. The stream is decoded by the project's clean-room Python decoder
(conformance/python), and every split record is priced two ways, in bits
per input vertex (order-0 entropy per level and context, plus 10 bits per
table entry, as decoder-core/examples/state_free_contexts.py does):

* as coded (SPEC §7.4): the two wing ranks in their contexts, the
  placement code in its context, the x and y residuals of the vector
  (z is the same under both and left out);
* positions first:
  - kind: R sat on an end of the edge (codes 0, 1) or midway (code 2);
  - the new vertex N (C for code 2) as its rank among the lattice points in
    R's real wedges (closed triangles in xy), R and the ring entries left
    out, nearest first to the ring's centroid (squared distance to
    S / n, compared as |n p - S|^2, exact), ties by y then x; in contexts
    by the number of candidates (up to 8). A fan whose bounding box holds
    more than CAP lattice points (default 1024), or a point outside the
    wedges, is an escape: its x and y residuals as coded today;
  - for code 2, P's offset from R - (C - R) (0 or 1 per axis);
  - the wings: N owns the ring's arc from entry x counter-clockwise to
    entry y, so the new triangles are (N, R, r_x) and (R, N, r_y) and N's
    wedges (N, r_t, r_t+1); only pairs that keep all of them counter-
    clockwise in xy (strictly) are eligible. x is ranked among the eligible
    x, then y among the eligible y with that x, both by the angle under
    which the entry sees the new edge, widest first (the Delaunay
    criterion), in contexts by the number of choices. A pair outside the
    eligible ones is an escape: its wing ranks as coded today. Which arc
    N owns also says whether N is P or C, so codes 0 and 1 need no symbol.

Standard library only.
"""
import collections
import math
import os
import sys

sys.path.insert(
    0, os.path.join(os.path.dirname(__file__), "..", "..", "conformance", "python")
)
import splitstream_decoder as sd  # noqa: E402

GHOST = sd.GHOST
TABLE_ENTRY_BITS = 10
ESCAPE = -1


def cross(o, u, v):
    return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])


def ccw(a, b, c):
    """A triangle with the ghost is virtual: it has no orientation."""
    return a is None or b is None or c is None or cross(a, b, c) > 0


def in_triangle(p, a, b, c):
    d = (cross(a, b, p), cross(b, c, p), cross(c, a, p))
    return not (min(d) < 0 < max(d))


def lattice_candidates(r2, ring_xy, cap):
    """Free lattice points of the fan in xy, or None past the cap."""
    k = len(ring_xy)
    wedges = [
        (r2, ring_xy[i], ring_xy[(i + 1) % k])
        for i in range(k)
        if ring_xy[i] is not None and ring_xy[(i + 1) % k] is not None
    ]
    points = [p for w in wedges for p in w] or [r2]
    x0, x1 = min(p[0] for p in points), max(p[0] for p in points)
    y0, y1 = min(p[1] for p in points), max(p[1] for p in points)
    if (x1 - x0 + 1) * (y1 - y0 + 1) > cap:
        return None
    taken = {r2} | {p for p in ring_xy if p is not None}
    return [
        (x, y)
        for y in range(y0, y1 + 1)
        for x in range(x0, x1 + 1)
        if (x, y) not in taken and any(in_triangle((x, y), *w) for w in wedges)
    ]


def eligible_pairs(ring_xy, ends, code):
    """Ordered pairs (x, y): N (or C) owns the arc from x to y."""
    k = len(ring_xy)
    pairs = []
    for x in range(k):
        for span in range(1, k):
            y = (x + span) % k
            if ring_xy[x] is None and ring_xy[y] is None:
                continue
            if code == 2:
                p, c = ends
                arcs = [(p, x, span), (c, y, k - span)]
                new = [(p, c, ring_xy[x]), (c, p, ring_xy[y])]
            else:
                r, n = ends
                arcs = [(n, x, span)]
                new = [(n, r, ring_xy[x]), (r, n, ring_xy[y])]
            if not all(ccw(*t) for t in new):
                continue
            if all(
                ccw(owner, ring_xy[(start + i) % k], ring_xy[(start + i + 1) % k])
                for owner, start, length in arcs
                for i in range(length)
            ):
                pairs.append((x, y))
    return pairs


def cos_seen(p, a, b):
    """Cosine of the angle under which p sees the segment a b."""
    u = (a[0] - p[0], a[1] - p[1])
    v = (b[0] - p[0], b[1] - p[1])
    nu, nv = math.hypot(*u), math.hypot(*v)
    return 1.0 if nu == 0 or nv == 0 else (u[0] * v[0] + u[1] * v[1]) / (nu * nv)


class Study(sd.Decoder):
    def __init__(self, data, cap):
        super().__init__(data, [])
        self.cap = cap
        self.level = 0
        self.rows = []

    def decode_level(self, li, lvl, entry):
        self.level = li
        return super().decode_level(li, lvl, entry)

    def read_record(self, R, ring, candset):
        # The coded wing ranks and placement code, with their contexts.
        seen = {}
        readers = [(self.subs[2], "u"), (self.subs[3], "v"), (self.subs[7], "code")]
        originals = [s.byte for s, _ in readers]
        for (sub, name), read in zip(readers, originals):
            def tapped(ctx=0, read=read, name=name):
                value = read(ctx)
                seen[name] = (ctx, value)
                return value
            sub.byte = tapped
        try:
            rec = super().read_record(R, ring, candset)
        finally:
            for (sub, _), read in zip(readers, originals):
                sub.byte = read
        if not self.constrained:
            raise SystemExit("positions_first.py: the stream is not constrained")
        o, d, _, _, p, c = rec
        pos, k = self.pos, len(ring)
        pr = pos[R]
        code = seen["code"][1]
        row = {"level": self.level, "u": seen["u"], "v": seen["v"], "code": seen["code"]}
        # The x and y residuals as coded (the linear prediction of §7.4).
        means = []
        for s in ([ring[o], ring[(o + d) % k]],
                  [ring[(o + i) % k] for i in range(1, d)],
                  [ring[(o + i) % k] for i in range(d + 1, k)]):
            s = [v for v in s if v != GHOST]
            sums = [sum(pos[v][a] - pr[a] for v in s) for a in range(2)]
            means.append([x // len(s) for x in sums] if s else [0, 0])
        m_w, m_1, m_2 = means
        own, other, weights = {0: (m_2, m_1, (1, 7, -2)), 1: (m_1, m_2, (1, 7, -2)),
                               2: (m_2, m_1, (0, 5, -5))}[code]
        lin = [(weights[0] * m_w[a] + weights[1] * own[a] + weights[2] * other[a]) >> 4
               for a in range(2)]
        vector = {0: [c[a] - pr[a] for a in range(2)], 1: [p[a] - pr[a] for a in range(2)],
                  2: [c[a] - p[a] for a in range(2)]}[code]
        row["xy"] = (vector[0] - lin[0], vector[1] - lin[1])
        # Positions first: the new vertex among the fan's free lattice points.
        r2 = (pr[0], pr[1])
        ring_xy = [None if v == GHOST else (pos[v][0], pos[v][1]) for v in ring]
        new = (p[0], p[1]) if code == 1 else (c[0], c[1])
        candidates = lattice_candidates(r2, ring_xy, self.cap)
        if candidates is None:
            row["rank"], row["choices"] = ESCAPE, 0
        else:
            real = [q for q in ring_xy if q is not None]
            n = len(real)
            sx, sy = sum(q[0] for q in real), sum(q[1] for q in real)
            candidates.sort(key=lambda q: ((n * q[0] - sx) ** 2 + (n * q[1] - sy) ** 2, q[1], q[0]))
            row["rank"] = candidates.index(new) if new in candidates else ESCAPE
            row["choices"] = len(candidates)
        row["delta"] = None
        if code == 2:
            row["delta"] = (p[0] - (2 * pr[0] - c[0]), p[1] - (2 * pr[1] - c[1]))
        # The wings among the pairs that keep xy orientations.
        ends = ((p[0], p[1]), (c[0], c[1])) if code == 2 else (r2, new)
        truth = ((o + d) % k, o) if code == 0 else (o, (o + d) % k)
        pairs = eligible_pairs(ring_xy, ends, code)
        if truth in pairs:
            a, b = ends
            key = lambda i: (2.0 if ring_xy[i] is None else cos_seen(ring_xy[i], a, b), i)  # noqa: E731
            xs = sorted({x for x, _ in pairs}, key=key)
            ys = sorted({y for x, y in pairs if x == truth[0]}, key=key)
            row["wx"], row["nx"] = xs.index(truth[0]), len(xs)
            row["wy"], row["ny"] = ys.index(truth[1]), len(ys)
        else:
            row["wx"] = row["wy"] = ESCAPE
            row["nx"] = row["ny"] = 0
        self.rows.append(row)
        return rec


def tables(rows, symbol, context):
    """Per level and context: counts of each symbol."""
    counts = collections.defaultdict(collections.Counter)
    for r in rows:
        counts[(r["level"], context(r))][symbol(r)] += 1
    return counts


def cost(rows, symbol, context, vertices):
    """Order-0 bits per vertex with one table per level and context."""
    bits = 0.0
    for counter in tables(rows, symbol, context).values():
        n = sum(counter.values())
        bits += sum(-x * math.log2(x / n) for x in counter.values())
        bits += TABLE_ENTRY_BITS * len(counter)
    return bits / vertices


def payload(rows, escaped, symbol, context, vertices):
    """Bits per vertex of the escaped rows' values under the full tables."""
    counts = tables(rows, symbol, context)
    bits = 0.0
    for r in rows:
        if escaped(r):
            counter = counts[(r["level"], context(r))]
            bits -= math.log2(counter[symbol(r)] / sum(counter.values()))
    return bits / vertices


def main():
    if len(sys.argv) not in (2, 3):
        raise SystemExit(__doc__)
    data = open(sys.argv[1], "rb").read()
    study = Study(data, int(sys.argv[2]) if len(sys.argv) == 3 else 1024)
    study.run()
    rows, v = study.rows, study.V
    up_to_8 = lambda n: min(n, 8)  # noqa: E731
    wing_u = cost(rows, lambda r: r["u"][1], lambda r: r["u"][0], v)
    wing_v = cost(rows, lambda r: r["v"][1], lambda r: r["v"][0], v)
    code = cost(rows, lambda r: r["code"][1], lambda r: r["code"][0], v)
    x = cost(rows, lambda r: r["xy"][0], lambda r: 0, v)
    y = cost(rows, lambda r: r["xy"][1], lambda r: 0, v)
    coded = wing_u + wing_v + code + x + y
    kind = cost(rows, lambda r: r["code"][1] == 2, lambda r: 0, v)
    rank = cost(rows, lambda r: r["rank"], lambda r: up_to_8(r["choices"]), v)
    n_escaped = lambda r: r["rank"] == ESCAPE  # noqa: E731
    rank_escapes = payload(rows, n_escaped, lambda r: r["xy"][0], lambda r: 0, v) + payload(
        rows, n_escaped, lambda r: r["xy"][1], lambda r: 0, v)
    delta = cost([r for r in rows if r["delta"] is not None], lambda r: r["delta"], lambda r: 0, v)
    wx = cost(rows, lambda r: r["wx"], lambda r: up_to_8(r["nx"]), v)
    wy = cost(rows, lambda r: r["wy"], lambda r: up_to_8(r["ny"]), v)
    w_escaped = lambda r: r["wx"] == ESCAPE  # noqa: E731
    wing_escapes = payload(rows, w_escaped, lambda r: r["u"][1], lambda r: r["u"][0], v) + payload(
        rows, w_escaped, lambda r: r["v"][1], lambda r: r["v"][0], v)
    first = kind + rank + rank_escapes + delta + wx + wy + wing_escapes
    splits = len(rows)
    print(f"{sys.argv[1]}: {v} vertices, {splits} splits; bits per input vertex")
    print(f"as coded:        wings {wing_u:.3f} + {wing_v:.3f}, placement code {code:.3f}, "
          f"x {x:.3f}, y {y:.3f}: {coded:.3f}")
    print(f"positions first: kind {kind:.3f}, new vertex {rank:.3f} + escapes {rank_escapes:.3f} "
          f"({sum(map(n_escaped, rows))} splits), midpoint offset {delta:.3f}, "
          f"wings {wx:.3f} + {wy:.3f} + escapes {wing_escapes:.3f} ({sum(map(w_escaped, rows))} splits): "
          f"{first:.3f}")
    print(f"difference: {first - coded:+.3f}")


if __name__ == "__main__":
    main()
