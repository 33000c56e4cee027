#!/usr/bin/env python3
"""What the split records would cost if every symbol's context came from
symbols read before it, never from the decoder's state (SPEC §5.5.5): the
measurement behind decoder-core/README.md, "Records decodable ahead".

Reads the tab-separated dump of the `split_fields` example:

    cargo run --release -p splitstream-decoder-core --features alloc \\
        --example split_fields -- IN.sps OUT.tsv
    python3 decoder-core/examples/state_free_contexts.py OUT.tsv...

and prints, per field, the order-0 cost in bits per split with one table
per level and context (entropy plus about 10 bits per table entry) under
the format's contexts and under contexts a decoder knows without its
state. The position residuals are left out: their contexts are fixed by
the level's plane policy and the value's place in its vector already.
Standard library only.
"""
import collections
import math
import sys

TABLE_ENTRY_BITS = 10


def clamp(x, lo, hi):
    return min(max(x, lo), hi)


def bits_per_split(rows, symbol, context):
    tables = collections.defaultdict(collections.Counter)
    for r in rows:
        tables[(r["level"], context(r))][symbol(r)] += 1
    bits = 0.0
    entries = 0
    for counts in tables.values():
        n = sum(counts.values())
        bits -= sum(c * math.log2(c / n) for c in counts.values())
        entries += len(counts)
    return (bits + TABLE_ENTRY_BITS * entries) / len(rows)


# Per field: the format's context first (SPEC §5.5.5), then state-free ones.
FIELDS = {
    "rank_o": [
        ("eligible count (format)", lambda r: clamp(r["m"], 2, 9)),
        ("none", lambda r: 0),
    ],
    "rank_d": [
        ("eligible count (format)", lambda r: clamp(r["m"], 2, 9)),
        ("none", lambda r: 0),
        ("rank_o", lambda r: clamp(r["rank_o"], 0, 3)),
    ],
    "symbol_p": [
        ("P's valence (format)", lambda r: clamp(r["valence_p"], 4, 8)),
        ("none", lambda r: 0),
        ("rank_d", lambda r: clamp(r["rank_d"], 0, 3)),
    ],
    "symbol_c": [
        ("P a leaf, C's valence (format)",
         lambda r: 0 if r["symbol_p"] == 0 else clamp(r["valence_c"], 4, 8) - 3),
        ("none", lambda r: 0),
        ("P a leaf", lambda r: r["symbol_p"] == 0),
        ("symbol_p", lambda r: clamp(r["symbol_p"], 0, 7)),
    ],
    "placement": [
        ("R between the arc means (format)", lambda r: r["placement_context"]),
        ("none", lambda r: 0),
        ("P, C leaves", lambda r: (r["symbol_p"] == 0, r["symbol_c"] == 0)),
    ],
}


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: state_free_contexts.py FIELDS.tsv...")
    for path in sys.argv[1:]:
        with open(path) as f:
            names = f.readline().split()
            rows = [dict(zip(names, map(int, line.split()))) for line in f]
        constrained = all(r["placement"] != 3 for r in rows)
        print(f"{path}: {len(rows)} splits, bits per split")
        now = free = 0.0
        for field, contexts in FIELDS.items():
            if field == "placement" and not constrained:
                continue
            costs = [(name, bits_per_split(rows, lambda r: r[field], ctx))
                     for name, ctx in contexts]
            best = min(costs[1:], key=lambda c: c[1])
            now += costs[0][1]
            free += best[1]
            print(f"  {field:9} " + "; ".join(f"{n} {c:.3f}" for n, c in costs))
        print(f"  all      format {now:.3f}, state-free {free:.3f} "
              f"(+{free - now:.3f} bits per split)")


if __name__ == "__main__":
    main()
