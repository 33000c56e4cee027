#!/usr/bin/env python3
"""A second splitstream 3.12 decoder, in Python, written from
decoder-core/SPEC.md and the protocol of conformance/README.md alone,
without reading the reference code: the check that the specification is
enough to decode bit-exactly. (Written for 3.0 from the SPEC alone; 3.1's
plane policy `height`, 3.2's wing policies, 3.3's deficit contexts and
3.4's rANS chunks beyond max_chunk_len were added with the SPEC sections
that define them; 3.5 added one level header check, level 0's
seed_triangles above its table entry's triangle_count failing
count-mismatch before the seed is read; 3.6's schedule `every-vertex`,
header flag bit 1, was added with the SPEC sections that define it, and
3.7's record order `positions-first`, level header byte 11, with SPEC §7.4
"Positions first", 3.8's tie rules of record orders 2 and 3 with
`off` of SPEC §7.4 `before`, 3.9's adaptive rANS tables with SPEC
§5.5.2 and §5.5.4, and 3.10's flag contexts `split-history` with SPEC
§5.1, §5.5.5, §6.1 and §7.5, and 3.11's `compact` level framing, header
flag bit 2, with SPEC §5.1.1: parse_fixed and parse_compact read a level
header up to its CRC check into the same fields, and decode_level applies
the rules after it to either; and 3.12's `compact` level table, header
flag bit 3 and table_len at offset 28, with SPEC §3.3 and §4.3: its
entries are read into the fields of a fixed entry, offset implied, and
go through §4.2's rules.) It speaks the conformance protocol (a stream
on stdin; the state hash after the seed and after every round, then `ok`,
or `error <class>`), so that .ci/test runs the vectors through it:

    target/debug/splitstream-conformance run \
        --decoder "python3 conformance/python/splitstream_decoder.py" --timeout 120

Standard library only. Written for clarity against the SPEC, not speed:
fine for the vectors, slow for large meshes.
"""
import functools
import struct
import sys
import zlib

MAGIC = b"\x89SPS\r\n\x1a\n"
LEAF = 0xFF
GHOST = -1
MAX_VERTICES = 0xFFFFFFFE
MAX_TRIANGLES = 0x55555554
STATE_LOW = 1 << 23
RANS_SLOT_BYTES = 1856
NCTX = {1: 1, 2: 8, 3: 8, 4: 1, 5: 5, 6: 3, 7: 5, 8: 3, 9: 1, 10: 1}
# Under the deficit contexts `valence` (3.3) deficit-p has 5, deficit-c 6.
NCTX_VALENCE = {**NCTX, 4: 5, 5: 6}
# Under the schedule `every-vertex` (3.6) flags has 5, by the valence.
NCTX_EVERY = {**NCTX, 1: 5}
# Under the record order `positions-first` (3.7) edge has 8, placement 7
# (SPEC §5.3, §5.5.5); on top of whichever table above applies.
NCTX_PF = {6: 8, 7: 7}


class Fail(Exception):
    def __init__(self, cls):
        Exception.__init__(self, cls)
        self.cls = cls


def crc32(b):
    return zlib.crc32(b) & 0xFFFFFFFF


def u16(s, o):
    return struct.unpack_from("<H", s, o)[0]


def u32(s, o):
    return struct.unpack_from("<I", s, o)[0]


def u64(s, o):
    return struct.unpack_from("<Q", s, o)[0]


def f64(s, o):
    return struct.unpack_from("<d", s, o)[0]


def f32(s, o):
    return struct.unpack_from("<f", s, o)[0]


def finite(x):
    return x == x and x not in (float("inf"), float("-inf"))


def round8(x):
    return (x + 7) // 8 * 8


def wrap(x):
    x &= 0xFFFFFFFF
    return x - (1 << 32) if x >= (1 << 31) else x


def rnd(p, q):
    if q < 0:
        p, q = -p, -q
    return (2 * p + q) // (2 * q)


def bitlen(x):
    return x.bit_length()


# ---------------------------------------------------------------- rANS
class Lane:
    __slots__ = ("x", "cur", "end", "data")


class Table:
    def __init__(self, freqs):
        self.f = freqs
        cum = [0]
        for f in freqs:
            cum.append(cum[-1] + f)
        self.cum = cum
        # slot -> token lookup
        look = bytearray(4096)
        for t, f in enumerate(freqs):
            for s in range(cum[t], cum[t + 1]):
                look[s] = t
        self.look = look


class Adaptive:
    """An adaptive table (SPEC §5.5.2, 3.9): m tokens, a rate, and per lane
    m - 1 probabilities (16-bit fractions of "above"), all one half, each
    with the count of its uses."""

    def __init__(self, m, rate, lane_count):
        self.m = m
        self.rate = rate
        self.q = [[1 << 15] * (m - 1) for _ in range(lane_count)]
        self.k = [[0] * (m - 1) for _ in range(lane_count)]


def leb128(next_byte):
    """SPEC §5.4 read_varint over the bytes `next_byte()` returns."""
    v = 0
    for i in range(5):
        b = next_byte()
        if i == 4 and b > 0x0F:
            raise Fail("malformed")
        v |= (b & 0x7F) << (7 * i)
        if b & 0x80 == 0:
            if b == 0 and i > 0:
                raise Fail("malformed")
            return v
    raise Fail("malformed")  # unreachable


def payload_varint(p, q):
    at = [q]

    def next_byte():
        if at[0] >= len(p):
            raise Fail("malformed")
        at[0] += 1
        return p[at[0] - 1]

    v = leb128(next_byte)
    return v, at[0]


def parse_rans(p, nctx, raw_len, lane_count):
    q = 0
    tables = []
    for _ in range(nctx):
        if q >= len(p):
            raise Fail("malformed")
        n = p[q]
        q += 1
        if n & 0x80:
            m = (n & 0x0F) + 1
            rate = 4 + ((n >> 4) & 7)
            if (m - 1) * lane_count > 48:
                raise Fail("malformed")
            tables.append(Adaptive(m, rate, lane_count))
            continue
        if n > 44:
            raise Fail("malformed")
        if n == 0:
            tables.append(None)
            continue
        c = []
        for _i in range(n):
            v, q = payload_varint(p, q)
            c.append(v)
        if c[n - 1] == 0:
            raise Fail("malformed")
        total = sum(c)
        f = [0 if ci == 0 else max(1, ci * 4096 // total) for ci in c]
        mx = max(f)
        j = f.index(mx)
        f[j] += 4096 - sum(f)
        if f[j] < 1:
            raise Fail("malformed")
        tables.append(Table(f))
    lens = []
    for _ in range(lane_count):
        v, q = payload_varint(p, q)
        lens.append(v)
    lanes = []
    start = q
    for i in range(lane_count):
        ln = lens[i]
        if start + ln > len(p):
            raise Fail("malformed")
        if i >= raw_len:
            if ln != 0:
                raise Fail("malformed")
            lanes.append(None)
        else:
            if ln < 4:
                raise Fail("malformed")
            x = u32(p, start)
            if not (STATE_LOW <= x < (1 << 31)):
                raise Fail("malformed")
            L = Lane()
            L.x = x
            L.cur = start + 4
            L.end = start + ln
            L.data = p
            lanes.append(L)
        start += ln
    if start != len(p):
        raise Fail("malformed")
    return tables, lanes


def renorm(L):
    while L.x < STATE_LOW:
        if L.cur == L.end:
            raise Fail("malformed")
        L.x = ((L.x << 8) | L.data[L.cur]) & 0xFFFFFFFFFFFF
        L.cur += 1


def adaptive_token(L, tab, lane):
    """SPEC §5.5.4: the token of an adaptive table, decision by decision."""
    q = tab.q[lane]
    k = tab.k[lane]
    for i in range(tab.m - 1):
        above = max(q[i] >> 4, 1)
        below = 4096 - above
        slot = L.x & 4095
        shift = min(tab.rate, 1 + k[i].bit_length())
        k[i] = min(k[i] + 1, 255)
        if slot < below:
            L.x = below * (L.x >> 12) + slot
            renorm(L)
            q[i] -= q[i] >> shift
            return i
        L.x = above * (L.x >> 12) + slot - below
        renorm(L)
        q[i] += (65536 - q[i]) >> shift
    return tab.m - 1


def decode_value(L, tab, lane):
    if tab is None:
        raise Fail("malformed")
    if isinstance(tab, Adaptive):
        t = adaptive_token(L, tab, lane)
    else:
        x = L.x
        slot = x & 4095
        t = tab.look[slot]
        c0 = tab.cum[t]
        L.x = tab.f[t] * (x >> 12) + slot - c0
        renorm(L)
    if t < 16:
        return t
    e = t - 12
    low = 0
    done = 0
    while done < e:
        step = min(e - done, 16)
        low |= (L.x & ((1 << step) - 1)) << done
        L.x >>= step
        renorm(L)
        done += step
    return (1 << e) + low


# ---------------------------------------------------------------- substreams
class Sub:
    def __init__(self, sid, chunks, lane_count, nctx):
        self.sid = sid
        self.nctx = nctx  # rANS tables per chunk (§5.3, §5.5.5)
        self.chunks = chunks  # list of (codec, raw_len, crc, payload)
        self.rans = bool(chunks) and chunks[0][0] == 2
        self.idx = 0
        self.buf = b""
        self.pos = 0
        self.len = 0
        self.cur = 0
        self.bi = 8
        self.lane_count = lane_count
        self.tables = None
        self.lanes = None

    def load(self):
        if self.idx >= len(self.chunks):
            raise Fail("count-mismatch")
        codec, raw_len, crc, payload = self.chunks[self.idx]
        self.idx += 1
        if crc32(payload) != crc:
            raise Fail("checksum-mismatch")
        if codec == 0:
            self.buf = payload
        elif codec == 1:
            try:
                d = zlib.decompressobj(-15)
                out = d.decompress(payload, raw_len + 1)
            except zlib.error:
                raise Fail("malformed")
            if (not d.eof) or d.unused_data or d.unconsumed_tail or len(out) != raw_len:
                raise Fail("malformed")
            self.buf = out
        else:
            self.tables, self.lanes = parse_rans(payload, self.nctx, raw_len, self.lane_count)
        self.len = raw_len
        self.pos = 0

    def value(self, ctx):
        if self.pos == self.len:
            self.load()
        lane = self.pos % self.lane_count
        v = decode_value(self.lanes[lane], self.tables[ctx], lane)
        self.pos += 1
        if self.pos == self.len:
            for L in self.lanes:
                if L is None:
                    continue
                if L.x != STATE_LOW or L.cur != L.end:
                    raise Fail("malformed")
        return v

    def _byte(self):
        if self.pos == self.len:
            self.load()
        b = self.buf[self.pos]
        self.pos += 1
        return b

    def _value_at_most(self, ctx, top):
        """A rANS value read for a field whose range ends at `top` (SPEC §5.5)."""
        v = self.value(ctx)
        if v > top:
            raise Fail("malformed")
        return v

    def byte(self, ctx=0):
        if self.rans:
            return self._value_at_most(ctx, 255)
        return self._byte()

    def bit(self, ctx=0):
        if self.rans:
            return self._value_at_most(ctx, 1)
        if self.bi == 8:
            self.cur = self._byte()
            self.bi = 0
        b = (self.cur >> self.bi) & 1
        self.bi += 1
        return b

    def varint(self, ctx=0):
        if self.rans:
            return self.value(ctx)
        return leb128(self._byte)

    def signed(self, ctx=0):
        u = self.varint(ctx)
        return (u >> 1) if u % 2 == 0 else -((u >> 1) + 1)

    def finish(self):
        if self.idx != len(self.chunks):
            raise Fail("count-mismatch")
        if self.pos != self.len:
            raise Fail("count-mismatch")
        if not self.rans and (self.cur >> self.bi) != 0 and self.bi < 8:
            raise Fail("count-mismatch")


# ---------------------------------------------------------------- positions first
# SPEC §7.4 Positions first (record order `positions-first`, format 3.7).
# Points are (x, y) pairs relative to R; a ring is given as its list `q` of
# q_i = (pos[r_i]_x - pos[R]_x, pos[r_i]_y - pos[R]_y), None for the ghost.
# Integers only; the SPEC's bounds keep every value below 2^52.
ORIGIN = (0, 0)


def orient(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def inside(p, a, b, c):
    """The closed triangle a, b, c holds p, either orientation."""
    s1 = orient(a, b, p)
    s2 = orient(b, c, p)
    s3 = orient(c, a, p)
    return (s1 >= 0 and s2 >= 0 and s3 >= 0) or (s1 <= 0 and s2 <= 0 and s3 <= 0)


def incircle(a, b, c, p):
    """> 0: p inside the circle through a, b, c (a, b, c counter-clockwise);
    the differences are taken relative to p."""
    rows = []
    for v in (a, b, c):
        dx = v[0] - p[0]
        dy = v[1] - p[1]
        rows.append((dx, dy, dx * dx + dy * dy))
    (ax, ay, al), (bx, by, bl), (cx, cy, cl) = rows
    return ax * (by * cl - bl * cy) - ay * (bx * cl - bl * cx) + al * (bx * cy - by * cx)


def free_points(q):
    """The fan's free lattice points, nearest the ring's centroid first, or
    None (an escape): a bounding box above 1,024 points, or no free point,
    or more than 255."""
    k = len(q)
    real = [p for p in q if p is not None]
    x0 = min([0] + [p[0] for p in real])
    x1 = max([0] + [p[0] for p in real])
    y0 = min([0] + [p[1] for p in real])
    y1 = max([0] + [p[1] for p in real])
    if (x1 - x0 + 1) * (y1 - y0 + 1) > 1024:
        return None
    wedges = [(q[i], q[(i + 1) % k]) for i in range(k)
              if q[i] is not None and q[(i + 1) % k] is not None
              and orient(ORIGIN, q[i], q[(i + 1) % k]) != 0]
    taken = set(real)
    F = []
    for x in range(x0, x1 + 1):
        for y in range(y0, y1 + 1):
            p = (x, y)
            if p == ORIGIN or p in taken:
                continue
            if any(inside(p, ORIGIN, a, b) for a, b in wedges):
                F.append(p)
    if len(F) == 0 or len(F) > 255:
        return None
    n = len(real)  # >= 1
    Sx = sum(p[0] for p in real)
    Sy = sum(p[1] for p in real)
    F.sort(key=lambda p: ((n * p[0] - Sx) ** 2 + (n * p[1] - Sy) ** 2, p[1], p[0]))
    return F


def bucket(f):
    """SPEC §5.5.5: the lattice rank's context is 3 + bucket(len(F))."""
    if f <= 1:
        return 0
    if f == 2:
        return 1
    if f <= 4:
        return 2
    if f <= 8:
        return 3
    return 4


def pair(x, y, q, Eset, kind, A, B):
    """Ring entries x, y as wings: A owns the arc from r_x counter-clockwise
    to r_y, B the rest, and every new triangle is counter-clockwise in xy."""
    k = len(q)
    if x not in Eset or y not in Eset or x == y:
        return False
    if kind == 1 and not x < y:
        return False
    if q[x] is not None and not orient(A, B, q[x]) > 0:  # triangle (A, B, r_x)
        return False
    if q[y] is not None and not orient(B, A, q[y]) > 0:  # triangle (B, A, r_y)
        return False
    for owner, first, last in ((A, x, y), (B, y, x)):  # A's wedges, then B's
        i = first
        while i != last:  # i = first .. last - 1 (mod k)
            j = (i + 1) % k
            if q[i] is not None and q[j] is not None and not orient(owner, q[i], q[j]) > 0:
                return False
            i = j
    return True


def off(a, b, p, order):
    """SPEC §7.4 off(i) (3.8): how many of the ends a, b see p along the
    diagonal the record order disfavours: dx = -dy under 2
    (positions-first-rising), dx = dy under 3 (positions-first-falling),
    none under 1."""
    n = 0
    for e in (a, b):
        dx, dy = p[0] - e[0], p[1] - e[1]
        if order == 2 and dx != 0 and dx == -dy:
            n += 1
        elif order == 3 and dx != 0 and dx == dy:
            n += 1
    return n


def before(a, b, q, order):
    """A sort key for the ring positions: u comes before w when w is the
    ghost and u is real, or both are real and incircle(a, b, q_w, q_u) > 0,
    or it is 0 and off(u) < off(w), or both are equal too and u < w."""

    def precedes(u, w):
        if q[w] is None and q[u] is not None:
            return True
        if q[u] is None or q[w] is None:
            return False
        c = incircle(a, b, q[w], q[u])
        if c != 0:
            return c > 0
        ou, ow = off(a, b, q[u], order), off(a, b, q[w], order)
        return ou < ow or (ou == ow and u < w)

    def cmp(u, w):
        if u == w:
            return 0
        if precedes(u, w):
            return -1
        if precedes(w, u):
            return 1
        return 0

    return functools.cmp_to_key(cmp)


# ---------------------------------------------------------------- decoder
class Decoder:
    def __init__(self, s, out):
        self.s = s
        self.out = out

    def emit_hash(self):
        V = self.V
        T = self.T
        parts = [struct.pack("<II", V, T)]
        pos = self.pos
        dfc = self.deficit
        pk = struct.Struct("<IIIB").pack
        parts.extend(pk(p[0], p[1], p[2], dfc[v]) for v, p in enumerate(pos))
        tri = self.tri
        parts.append(struct.pack("<%dI" % len(tri), *tri))
        data = b"".join(parts)
        h = 0xCBF29CE484222325
        for b in data:
            h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
        self.out.append("%016x" % h)

    def run(self):
        s = self.s
        n = len(s)
        # header
        if n < 8:
            raise Fail("truncated")
        if s[0:8] != MAGIC:
            raise Fail("bad-magic")
        if n < 10:
            raise Fail("truncated")
        if s[8] != 3:
            raise Fail("unsupported-version")
        if n < 96:
            raise Fail("truncated")
        if crc32(s[0:92]) != u32(s, 92):
            raise Fail("checksum-mismatch")
        flags = u16(s, 10)
        if flags & 0xFFF0:  # bit 1: schedule (3.6), bit 2: framing (3.11), bit 3: table (3.12)
            raise Fail("malformed")
        if not (1 <= s[12] <= 31):
            raise Fail("malformed")
        compact_table = (flags >> 3) & 1  # table: 0 fixed, 1 compact (3.12), SPEC §4.3
        if compact_table and not (flags >> 2) & 1:  # only with the compact framing
            raise Fail("malformed")
        table_len = u32(s, 28)
        if (not compact_table and table_len != 0) or u32(s, 88) != 0:
            raise Fail("malformed")
        if not (1 <= s[13] <= 32):
            raise Fail("malformed")
        if u16(s, 14) == 0:
            raise Fail("malformed")
        if compact_table:
            L = u16(s, 14)
            if L > 255 or not (8 * L + 4 <= table_len <= 24 * L + 4):
                raise Fail("malformed")
        vcap = u32(s, 16)
        tcap = u32(s, 20)
        mcl = u32(s, 24)
        if vcap == 0 or vcap > MAX_VERTICES:
            raise Fail("malformed")
        if tcap == 0 or tcap > MAX_TRIANGLES:
            raise Fail("malformed")
        if mcl == 0:
            raise Fail("malformed")
        for k in range(3):
            if not finite(f64(s, 32 + 8 * k)):
                raise Fail("malformed")
            sc = f64(s, 56 + 8 * k)
            if not finite(sc) or sc <= 0:
                raise Fail("malformed")
        self.constrained = flags & 1
        self.every = (flags >> 1) & 1  # schedule: 0 split-valences, 1 every-vertex (3.6)
        self.compact = (flags >> 2) & 1  # framing: 0 fixed, 1 compact (3.11), SPEC §5.1.1
        self.bits = s[12]
        self.lane_count = s[13]
        L = u16(s, 14)
        self.vcap = vcap
        self.tcap = tcap
        self.mcl = mcl
        wsb = u64(s, 80)
        # level table
        head_len = 96 + table_len if compact_table else 96 + 32 * L + 4
        if n < head_len:
            raise Fail("truncated")
        if crc32(s[96:head_len - 4]) != u32(s, head_len - 4):
            raise Fail("checksum-mismatch")
        expected = head_len
        entries = []
        at = [96]
        end = head_len - 4

        def next_byte():  # compact table (3.12): the CRC matched, so past `end` is malformed
            if at[0] + 1 > end:
                raise Fail("malformed")
            at[0] += 1
            return s[at[0] - 1]

        for k in range(L):
            if compact_table:  # SPEC §4.3: varints and an f32; offset implied, no reserved
                length = leb128(next_byte)
                dv = leb128(next_byte)
                dt = leb128(next_byte)
                rounds = leb128(next_byte)
                if at[0] + 4 > end:
                    raise Fail("malformed")
                p = entries[k - 1] if k else dict(V=0, T=0)
                e = dict(offset=expected, length=length, V=p["V"] + dv, T=p["T"] + dt,
                         rounds=rounds, gerr=f32(s, at[0]), res=0)
                at[0] += 4
            else:
                o = 96 + 32 * k
                e = dict(offset=u64(s, o), length=u32(s, o + 8), V=u32(s, o + 12), T=u32(s, o + 16),
                         rounds=u32(s, o + 20), gerr=f32(s, o + 24), res=u32(s, o + 28))
            if e["res"] != 0:
                raise Fail("malformed")
            if e["offset"] != expected:
                raise Fail("malformed")
            expected = e["offset"] + e["length"]
            g = e["gerr"]
            if not finite(g) or g < 0:
                raise Fail("malformed")
            if e["V"] > vcap or e["T"] > tcap:
                raise Fail("capacity-exceeded")
            if k == 0:
                if e["V"] == 0 or e["T"] == 0 or e["rounds"] > e["V"]:
                    raise Fail("malformed")
            else:
                p = entries[k - 1]
                dv = e["V"] - p["V"]
                dt = e["T"] - p["T"]
                if not (e["rounds"] >= 1 and dv >= e["rounds"] and dt >= 1 and dv <= dt <= 2 * dv):
                    raise Fail("malformed")
            entries.append(e)
        if compact_table and at[0] != end:  # bytes left in the table
            raise Fail("malformed")
        last = entries[-1]
        if last["V"] != vcap or last["T"] != tcap:
            raise Fail("malformed")
        self.entries = entries
        # workspace
        if wsb != self.workspace(vcap, tcap, entries[0]["V"], entries[0]["T"], mcl):
            raise Fail("malformed")
        self.V = 0
        self.T = 0
        for li in range(L):
            e = entries[li]
            if e["offset"] + e["length"] > n:
                raise Fail("truncated")
            lvl = s[e["offset"]:e["offset"] + e["length"]]
            self.decode_level(li, lvl, e)

    @staticmethod
    def workspace(V, T, V0, T0, M):
        w = 3 if 3 * T <= (1 << 24) - 1 else 4
        sizes = [12 * V, 12 * T, max(w * 3 * T + 1, 4 * (6 * T0 + V0 + 1)), w * V + 1, V,
                 3 * 8 * ((V + 63) // 64), 7 * round8(max(M, RANS_SLOT_BYTES))]
        return sum(round8(x) for x in sizes)

    def parse_fixed(self, li, lvl):
        """SPEC §5.1: the fixed level header, up to and including its CRC
        check. Returns its fields as parse_compact does: R, N, the policy
        bytes, SV and ST (level 0), the split counts, the directory entries
        (id, codec, reserved, raw_len, stored_len, crc) and payload_start."""
        ln = len(lvl)
        H = 20 if li == 0 else 12
        if ln < H:
            raise Fail("truncated")
        R = u32(lvl, 0)
        N = u32(lvl, 4)
        SV = ST = None
        if li == 0:
            SV = u32(lvl, 12)
            ST = u32(lvl, 16)
        payload_start = H + 4 + 4 * R + 16 * N
        if ln < payload_start:
            raise Fail("truncated")
        if crc32(lvl[0:payload_start - 4]) != u32(lvl, payload_start - 4):
            raise Fail("checksum-mismatch")
        # past the CRC check every field lies within the level: reading them
        # all now fails nothing
        policies = tuple(lvl[8:12])
        split_counts = [u32(lvl, H + 4 * r) for r in range(R)]
        dir_off = H + 4 * R
        entries = []
        for i in range(N):
            o = dir_off + 16 * i
            entries.append((lvl[o], lvl[o + 1], u16(lvl, o + 2),
                            u32(lvl, o + 4), u32(lvl, o + 8), u32(lvl, o + 12)))
        return R, N, policies, SV, ST, split_counts, entries, payload_start

    def parse_compact(self, li, lvl):
        """Compact framing (3.11), SPEC §5.1.1: the level header read field by
        field from a cursor, up to and including its CRC check; the same
        fields as parse_fixed (a compact entry has no reserved field: 0)."""
        ln = len(lvl)
        at = [0]

        def next_byte():
            if ln < at[0] + 1:
                raise Fail("truncated")
            at[0] += 1
            return lvl[at[0] - 1]

        def varint():  # §5.4's rules: at most 5 bytes, 32 bits, minimal
            return leb128(next_byte)

        R = varint()
        N = varint()
        if ln < at[0] + 4:
            raise Fail("truncated")
        policies = tuple(lvl[at[0]:at[0] + 4])  # plane, wing, contexts, record order
        at[0] += 4
        SV = ST = None
        if li == 0:
            SV = varint()
            ST = varint()
        # every step reads at least one byte: a count above what the level
        # holds ends in `truncated`
        split_counts = [varint() for _r in range(R)]
        entries = []
        for _i in range(N):
            b = next_byte()  # id_codec: id in bits 0-3, codec in bits 4-7
            raw_len = varint()
            stored_len = varint()
            if ln < at[0] + 4:
                raise Fail("truncated")
            crc = u32(lvl, at[0])
            at[0] += 4
            entries.append((b & 0x0F, b >> 4, 0, raw_len, stored_len, crc))
        payload_start = at[0] + 4
        if ln < payload_start:
            raise Fail("truncated")
        if crc32(lvl[0:at[0]]) != u32(lvl, at[0]):
            raise Fail("checksum-mismatch")
        return R, N, policies, SV, ST, split_counts, entries, payload_start

    def decode_level(self, li, lvl, entry):
        ln = len(lvl)
        if self.compact:  # compact framing (3.11), SPEC §5.1.1
            hdr = self.parse_compact(li, lvl)
        else:  # fixed framing, SPEC §5.1
            hdr = self.parse_fixed(li, lvl)
        R, N, policies, SV, ST, split_counts, dir_entries, payload_start = hdr
        # SPEC §5.1 (and §5.1.1): every rule after the CRC check, in order,
        # whatever the framing
        plane_policy, wing_policy, contexts, record_order = policies
        if plane_policy > 5:
            raise Fail("malformed")
        if wing_policy > 2:  # wing policy (3.2)
            raise Fail("malformed")
        if contexts > 2:  # contexts (3.3; 2 since 3.10)
            raise Fail("malformed")
        if contexts == 1 and self.every:  # no split-valence symbols (3.6)
            raise Fail("malformed")
        if contexts == 2 and not self.every:  # split-history: every-vertex only (3.10)
            raise Fail("malformed")
        if record_order > 3:  # record order (3.7; 2 and 3 since 3.8)
            raise Fail("malformed")
        if record_order >= 1 and (not self.constrained or plane_policy != 5):
            raise Fail("malformed")  # positions-first: constrained mode, plane policy height
        if li == 0 and (SV == 0 or ST == 0):
            raise Fail("malformed")
        allowed = range(1, 11) if li == 0 else range(1, 8)
        prev_id = 0
        prev_rans = False
        total = payload_start
        chunks = {}
        for sid, codec, res, raw_len, stored_len, crc in dir_entries:
            if res != 0:
                raise Fail("malformed")
            if sid not in allowed:
                raise Fail("malformed")
            if sid < prev_id:
                raise Fail("malformed")
            rans = codec == 2
            if sid == prev_id and rans != prev_rans:
                raise Fail("malformed")
            prev_id = sid
            prev_rans = rans
            # max_chunk_len bounds stored and deflate chunks only (3.4):
            # a rANS chunk may code any number of values.
            if raw_len == 0 or (not rans and raw_len > self.mcl):
                raise Fail("malformed")
            if codec == 0 and stored_len != raw_len:
                raise Fail("malformed")
            if codec > 2:
                raise Fail("malformed")
            chunks.setdefault(sid, []).append((codec, raw_len, crc, total, stored_len))
            total += stored_len
        if total > ln:
            raise Fail("truncated")
        if total < ln:
            raise Fail("malformed")
        if R != entry["rounds"]:
            raise Fail("count-mismatch")
        for sc in split_counts:
            if sc == 0:
                raise Fail("malformed")
        before = SV if li == 0 else self.entries[li - 1]["V"]
        if before + sum(split_counts) != entry["V"]:
            raise Fail("count-mismatch")
        if li == 0 and ST > entry["T"]:  # the seed fits level 0's entry (3.5)
            raise Fail("count-mismatch")
        subs = {}
        for sid in range(1, 11):
            lst = [(c, rl, crc, bytes(lvl[off:off + sl])) for (c, rl, crc, off, sl) in chunks.get(sid, [])]
            nctx = (NCTX_EVERY if self.every else NCTX_VALENCE if contexts == 1 else NCTX)[sid]
            if self.every and contexts == 2 and sid == 1:  # split-history flags (3.10)
                nctx = 8
            if record_order >= 1:  # positions first (3.7, 3.8)
                nctx = NCTX_PF.get(sid, nctx)
            subs[sid] = Sub(sid, lst, self.lane_count, nctx)
        self.subs = subs
        self.policy = plane_policy
        self.wing_policy = wing_policy
        self.deficit_contexts = contexts
        # SPEC §6.1 (3.10): the split-history bits, all 0 when a level starts.
        self.split = set()
        # 0 wings-first, 1 positions-first (3.7), 2 positions-first-rising,
        # 3 positions-first-falling (3.8)
        self.record_order = record_order
        self.T_l = entry["T"]
        if li == 0:
            self.read_base(SV, ST)
        for r in range(R):
            self.run_round(split_counts[r])
            self.emit_hash()
        for sid in range(1, 8):
            subs[sid].finish()
        if self.V != entry["V"] or self.T != entry["T"]:
            raise Fail("count-mismatch")

    # ------------------------------------------------------------ base
    def read_base(self, V0, T0):
        subs = self.subs
        sp = subs[8]
        lim = 1 << self.bits
        prev = [0, 0, 0]
        pos = []
        for v in range(V0):
            for k in range(3):
                prev[k] += sp.signed(k)
            for k in range(3):
                if prev[k] < 0 or prev[k] >= lim:
                    raise Fail("position-out-of-range")
            pos.append(list(prev))
        st = subs[9]
        tri = []
        for t in range(T0):
            tri.append(st.varint(0))
            tri.append(st.varint(0))
            tri.append(st.varint(0))
        sd = subs[10]
        # every-vertex (3.6): base-deficits holds no values; the valences
        # are set by the validation below (SPEC §6.3)
        deficit = [0] * V0 if self.every else [sd.byte(0) for v in range(V0)]
        for sid in (8, 9, 10):
            subs[sid].finish()
        # validate
        for t in range(T0):
            a, b, c = tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]
            if a >= V0 or b >= V0 or c >= V0:
                raise Fail("non-manifold")
            if a == b or b == c or a == c:
                raise Fail("non-manifold")
        vtri = [[] for _ in range(V0)]
        for t in range(T0):
            for i in range(3):
                vtri[tri[3 * t + i]].append(t)
        for v in range(V0):
            if not vtri[v]:
                raise Fail("non-manifold")
            seen = set()
            for t in vtri[v]:
                for i in range(3):
                    if tri[3 * t + i] == v:
                        u = tri[3 * t + (i + 1) % 3]
                        if u in seen:
                            raise Fail("non-manifold")
                        seen.add(u)
        self.pos = pos
        self.tri = tri
        self.deficit = deficit
        self.vtri = [set(x) for x in vtri]
        self.V = V0
        self.T = T0
        for v in range(V0):
            nxt = {}
            for t in vtri[v]:
                a, b, c = tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]
                if a == v:
                    nxt[b] = c
                elif b == v:
                    nxt[c] = a
                else:
                    nxt[a] = b
            targets = set(nxt.values())
            starts = [u for u in nxt if u not in targets]
            cnt = len(nxt)
            if starts:
                u = starts[0]
                steps = 0
                while u in nxt:
                    u = nxt[u]
                    steps += 1
                if steps != cnt:
                    raise Fail("non-manifold")
                val = cnt + 2
            else:
                u0 = next(iter(nxt))
                u = nxt[u0]
                steps = 1
                while u != u0:
                    u = nxt[u]
                    steps += 1
                if steps != cnt or cnt < 3:
                    raise Fail("non-manifold")
                val = cnt
            if self.every:
                deficit[v] = min(val, 255)  # 3.6: the valence (§6.2)
            elif deficit[v] != LEAF and val + deficit[v] > 255:
                raise Fail("valence-overflow")
        self.emit_hash()

    # ------------------------------------------------------------ rings
    def ring(self, R):
        tri = self.tri
        nxt = {}
        tof = {}
        for t in self.vtri[R]:
            a, b, c = tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]
            if a == R:
                u, w = b, c
            elif b == R:
                u, w = c, a
            else:
                u, w = a, b
            nxt[u] = w
            tof[u] = t
        targets = set(nxt.values())
        starts = [u for u in nxt if u not in targets]
        if starts:
            u = starts[0]
            ring = [GHOST, u]
            while u in nxt:
                u = nxt[u]
                ring.append(u)
        else:
            u0 = min(nxt)
            ring = [u0]
            u = nxt[u0]
            while u != u0:
                ring.append(u)
                u = nxt[u]
        if len(ring) > 255:
            raise Fail("valence-overflow")
        return ring, tof

    # ------------------------------------------------------------ rounds
    def run_round(self, s):
        n = self.V
        if n + s > self.vcap:
            raise Fail("capacity-exceeded")
        deficit = self.deficit
        if self.every:  # 3.6: every vertex
            cand = range(n)
        else:
            cand = [v for v in range(n) if deficit[v] == 0]
        candset = set(cand)
        flags = self.subs[1]
        flagged = []
        blocked = set()
        rings = {}
        for v in cand:
            if v in blocked:
                continue
            # context 0; every-vertex (3.6): by the valence byte, as at
            # round start (all flags are read before any split), §5.5.5
            if not self.every:
                fctx = 0
            elif self.deficit_contexts == 2:  # split-history (3.10)
                fctx = min(max(deficit[v], 5), 8) - 5 + 4 * (v in self.split)
            else:
                fctx = min(max(deficit[v], 4), 8) - 4
            if flags.bit(fctx) == 1:
                flagged.append(v)
                rg = self.ring(v)
                rings[v] = rg
                for x in rg[0]:
                    if x != GHOST:
                        blocked.add(x)
        if len(flagged) != s:
            raise Fail("count-mismatch")
        for j, R in enumerate(flagged):
            ring, tof = self.ring(R)
            if self.record_order >= 1:  # positions first (3.7, 3.8)
                rec = self.read_record_pf(R, ring, candset)
            else:
                rec = self.read_record(R, ring, candset)
            self.apply_split(R, ring, tof, rec, n + j)

    def eligible(self, ring, candset):
        """SPEC §7.4 step 1: the ring positions that may be wings, ascending."""
        if self.every:  # 3.6: every entry is eligible
            return list(range(len(ring)))
        return [i for i in range(len(ring)) if ring[i] == GHOST or ring[i] not in candset]

    def read_deficits(self, k, d):
        """SPEC §7.4 step 2: the deficits of P and C from the wings' d."""
        subs = self.subs
        valP = d + 2
        valC = k - d + 2
        if self.every:  # 3.6: nothing read, the bytes are the valences
            return min(valP, 255), min(valC, 255)
        if self.deficit_contexts == 0:  # plain
            pctx = 0
        else:  # valence (3.3)
            pctx = min(max(valP, 4), 8) - 4
        dP = self.deficit_of(subs[4].byte(pctx), valP)
        if self.deficit_contexts == 0:
            cctx = 4 if dP == LEAF else min(max(valC, 3), 6) - 3
        else:
            cctx = 0 if dP == LEAF else min(max(valC, 4), 8) - 3
        dC = self.deficit_of(subs[5].byte(cctx), valC)
        return dP, dC

    @staticmethod
    def place(code, pR, X):
        """SPEC §7.4 place(): P and C from R and the vector X."""
        if code == 0:
            P = list(pR)
            Cp = [pR[ax] + X[ax] for ax in range(3)]
        elif code == 1:
            P = [pR[ax] + X[ax] for ax in range(3)]
            Cp = list(pR)
        else:
            P = [pR[ax] - (X[ax] >> 1) for ax in range(3)]
            Cp = [P[ax] + X[ax] for ax in range(3)]
        return P, Cp

    def check_positions(self, P, Cp):
        """SPEC §7.4: every coordinate of P, then of C, in 0 .. 2^bits."""
        lim = 1 << self.bits
        for X in (P, Cp):
            for ax in range(3):
                if X[ax] < 0 or X[ax] >= lim:
                    raise Fail("position-out-of-range")

    def read_record(self, R, ring, candset):
        subs = self.subs
        k = len(ring)
        E = self.eligible(ring, candset)
        m = len(E)
        ctx = min(max(m, 2), 9) - 2
        op = subs[2].byte(ctx)
        dp = subs[3].byte(ctx)
        if self.wing_policy == 0:
            if dp == 0 or op + dp >= m:
                raise Fail("ring-offset-out-of-range")
            o = E[op]
            d = E[op + dp] - o
        else:
            o, d = self.near_wings(ring, E, op, dp)
        dP, dC = self.read_deficits(k, d)
        # arc means
        pos = self.pos
        pR = pos[R]
        W = [ring[o], ring[(o + d) % k]]
        I1 = [ring[(o + i) % k] for i in range(1, d)]
        I2 = [ring[(o + i) % k] for i in range(d + 1, k)]
        means = []
        sums = []
        cnts = []
        for S in (W, I1, I2):
            S = [v for v in S if v != GHOST]
            sm = [0, 0, 0]
            for v in S:
                pv = pos[v]
                for ax in range(3):
                    sm[ax] += pv[ax] - pR[ax]
            ns = len(S)
            means.append([x // ns for x in sm] if ns else [0, 0, 0])
            sums.append(sm)
            cnts.append(ns)
        mW, mI1, mI2 = means
        G = [sums[0][ax] + sums[1][ax] + sums[2][ax] for ax in range(3)]
        nG = sum(cnts)
        a = ring[o]
        b = ring[(o + d) % k]
        if a != GHOST and b != GHOST:
            e = [pos[b][ax] - pos[a][ax] for ax in range(3)]
        else:
            e = None
        plane = self.plane_of(e, mI1, mI2)

        def lin(wW, wo, wt, own, oth):
            return [(wW * mW[ax] + wo * own[ax] + wt * oth[ax]) >> 4 for ax in range(3)]

        if self.constrained:
            aa = [mI2[ax] - mI1[ax] for ax in range(3)]
            Tt = -(G[0] * aa[0] + G[1] * aa[1] + G[2] * aa[2])
            Q = nG * (aa[0] ** 2 + aa[1] ** 2 + aa[2] ** 2)
            if 10 * Tt < -5 * Q:
                pc = 0
            elif 10 * Tt < -Q:
                pc = 1
            elif 10 * Tt <= Q:
                pc = 2
            elif 10 * Tt <= 5 * Q:
                pc = 3
            else:
                pc = 4
            code = subs[7].byte(pc)
            if code > 2:
                raise Fail("malformed")
            if code == 0:
                lp = lin(1, 7, -2, mI2, mI1)
            elif code == 1:
                lp = lin(1, 7, -2, mI1, mI2)
            else:
                lp = lin(0, 5, -5, mI2, mI1)
            r = self.read_vector(subs[6], plane)
            X = self.vector(lp, r, code, ring, pR)
            P, Cp = self.place(code, pR, X)
        else:
            lp = lin(1, 4, -1, mI1, mI2)
            r = self.read_vector(subs[6], plane)
            X = self.vector(lp, r, "P", ring, pR)
            P = [pR[ax] + X[ax] for ax in range(3)]
            lc = lin(1, 4, -1, mI2, mI1)
            r = self.read_vector(subs[7], plane)
            X = self.vector(lc, r, "C", ring, pR)
            Cp = [pR[ax] + X[ax] for ax in range(3)]
        self.check_positions(P, Cp)
        return (o, d, dP, dC, P, Cp)

    def read_record_pf(self, R, ring, candset):
        """SPEC §7.4 Positions first (3.7): the new vertex as a free lattice
        point of the fan, then the wings among the pairs that keep the new
        triangles counter-clockwise; read_record for an escape."""
        subs = self.subs
        k = len(ring)
        pos = self.pos
        pR = pos[R]
        q = [None if v == GHOST else (pos[v][0] - pR[0], pos[v][1] - pR[1]) for v in ring]
        F = free_points(q)
        if F is None:
            return self.read_record(R, ring, candset)  # escape
        kind = subs[7].byte(5)
        if kind > 2:
            raise Fail("malformed")
        if kind == 2:
            return self.read_record(R, ring, candset)  # escape
        j = subs[6].varint(3 + bucket(len(F)))
        if j >= len(F):
            raise Fail("position-out-of-range")
        N = F[j]
        t = 0
        if kind == 0:  # R stays at one end of the edge
            A = N  # the new vertex
            B = ORIGIN  # R
        else:  # kind 1: R sat on the floor midpoint
            t = subs[7].byte(6)
            if t > 3:
                raise Fail("malformed")
            A = (-N[0] + (t & 1), -N[1] + (t >> 1))  # P = 2R - C + t, per axis
            B = N  # C
        E = self.eligible(ring, candset)
        Eset = set(E)
        xs = [x for x in E if any(pair(x, y, q, Eset, kind, A, B) for y in E)]
        xs.sort(key=before(A, B, q, self.record_order))
        u = subs[2].byte(min(max(len(xs), 1), 8) - 1)
        if u >= len(xs):
            raise Fail("ring-offset-out-of-range")
        x = xs[u]
        ys = [y for y in E if pair(x, y, q, Eset, kind, A, B)]
        ys.sort(key=before(B, A, q, self.record_order))
        v = subs[3].byte(min(len(ys), 8) - 1)
        if v >= len(ys):
            raise Fail("ring-offset-out-of-range")
        y = ys[v]
        if x < y:  # A owns arc 1: A is P
            o, d = x, y - x
        else:  # A owns arc 2: A is C (kind 0 only)
            o, d = y, x - y
        code = 2 if kind == 1 else (1 if x < y else 0)
        dP, dC = self.read_deficits(k, d)
        rz = subs[6].signed(2)
        if code == 2:  # C - P
            Xxy = (2 * N[0] - (t & 1), 2 * N[1] - (t >> 1))
        else:  # C - R (code 0) or P - R (code 1)
            Xxy = N
        h = self.height_of(code, Xxy, ring, pR)
        if h is None:
            h = 0
        X = [Xxy[0], Xxy[1], wrap(h + rz)]
        P, Cp = self.place(code, pR, X)
        self.check_positions(P, Cp)
        return (o, d, dP, dC, P, Cp)

    def vector(self, lp, r, target, ring, pR):
        # SPEC §7.4 vector(): the linear prediction plus the residual, and
        # under plane policy 5 (height, 3.1) z from the surface of R's fan.
        X = [wrap(lp[ax] + r[ax]) for ax in range(3)]
        if self.policy == 5:
            h = self.height_of(target, X, ring, pR)
            if h is not None:
                X[2] = wrap(h + r[2])
        return X

    def height_of(self, target, X, ring, pR):
        if target == 2:
            p = (-(X[0] >> 1), -(X[1] >> 1))
            c = (p[0] + X[0], p[1] + X[1])
            hc = self.surface(c, ring, pR)
            hp = self.surface(p, ring, pR)
            if hc is None or hp is None:
                return None
            return hc - hp
        return self.surface((X[0], X[1]), ring, pR)

    def surface(self, y, ring, pR):
        k = len(ring)
        for i in range(k):
            u, v = ring[i], ring[(i + 1) % k]
            if u == GHOST or v == GHOST:
                continue
            a = [self.pos[u][ax] - pR[ax] for ax in range(3)]
            b = [self.pos[v][ax] - pR[ax] for ax in range(3)]
            det = a[0] * b[1] - a[1] * b[0]
            if det == 0:
                continue
            s = y[0] * b[1] - y[1] * b[0]
            t = a[0] * y[1] - a[1] * y[0]
            if (det > 0 and s >= 0 and t >= 0) or (det < 0 and s <= 0 and t <= 0):
                return rnd(s * a[2] + t * b[2], det)
        return None

    def near_wings(self, ring, E, u, v):
        # SPEC 7.4 (3.2): the wings in the near order.
        k = len(ring)
        real = [self.pos[x] for x in ring if x != GHOST]
        n = len(real)
        centre = [sum(p[a] for p in real) // max(n, 1) for a in range(3)]
        axes = 3 if self.wing_policy == 1 else 2
        cap = (1 << 47) - 1

        def K(i):
            if ring[i] == GHOST:
                key = cap
            else:
                p = self.pos[ring[i]]
                key = min(sum((p[a] - centre[a]) ** 2 for a in range(axes)), cap)
            return key * 256 + i

        order = sorted(K(i) for i in E)
        if u >= len(order):
            raise Fail("ring-offset-out-of-range")
        first = order[u]
        f = first & 0xFF

        def balance(j):
            return abs(2 * ((j - f) % k) - k)

        rest = sorted((balance(x & 0xFF) << 55) | x for x in order if x > first)
        if v >= len(rest):
            raise Fail("ring-offset-out-of-range")
        s = rest[v] & 0xFF
        a, b = min(f, s), max(f, s)
        return a, b - a

    @staticmethod
    def deficit_of(sym, val):
        if sym == 0:
            return LEAF
        if sym + 2 < val or sym + 2 > 255:
            raise Fail("valence-overflow")
        return sym + 2 - val

    def plane_of(self, e, mI1, mI2):
        pol = self.policy
        if pol == 0 or pol == 5:  # off, height (3.1): no plane
            return None
        q = [mI2[ax] - mI1[ax] for ax in range(3)]
        if e is not None:
            N = [e[1] * q[2] - e[2] * q[1], e[2] * q[0] - e[0] * q[2], e[0] * q[1] - e[1] * q[0]]
        else:
            N = [0, 0, 0]
        s = max(0, bitlen(max(abs(x) for x in N)) - 15)
        nn = [x >> s for x in N]
        if pol == 1:
            best = 0
            for ax in (1, 2):
                if abs(nn[ax]) > abs(nn[best]):
                    best = ax
            j = best
        else:
            j = pol - 2
        return (nn, j)

    def read_vector(self, sub, plane):
        if plane is None:
            return [sub.signed(0), sub.signed(1), sub.signed(2)]
        nn, j = plane
        j1 = (j + 1) % 3
        j2 = (j + 2) % 3
        if self.policy == 1:
            c1, c2, c3 = 0, 0, 1
        else:
            c1, c2, c3 = j1, j2, j
        r = [0, 0, 0]
        r[j1] = sub.signed(c1)
        r[j2] = sub.signed(c2)
        rp = sub.signed(c3)
        if nn[j] != 0:
            r[j] = wrap(rp + rnd(-(nn[j1] * r[j1] + nn[j2] * r[j2]), nn[j]))
        else:
            r[j] = rp
        return r

    def apply_split(self, R, ring, tof, rec, C):
        o, d, dP, dC, P, Cp = rec
        k = len(ring)
        if d == 0 or o + d >= k:
            raise Fail("ring-offset-out-of-range")
        a = ring[o]
        b = ring[o + d]
        valP = d + 2
        valC = k - d + 2
        deficit = self.deficit
        if not self.every:  # no check under every-vertex (3.6)
            if dP != LEAF and valP + dP > 255:
                raise Fail("valence-overflow")
            if dC != LEAF and valC + dC > 255:
                raise Fail("valence-overflow")
            for w in (a, b):
                if w != GHOST and deficit[w] == 0:
                    raise Fail("valence-overflow")
        added = (a != GHOST) + (b != GHOST)
        if self.T + added > self.T_l:
            raise Fail("count-mismatch")
        if self.V + 1 > self.vcap or self.T + added > self.tcap:
            raise Fail("capacity-exceeded")
        for w in (a, b):
            if w == GHOST:
                continue
            if self.every:  # 3.6: the wing's valence grows by 1
                deficit[w] = min(deficit[w] + 1, 255)
            elif deficit[w] != LEAF:
                deficit[w] -= 1
        tri = self.tri
        vtri = self.vtri
        vtri.append(set())
        for i in range(o + d, o + k):
            ri = ring[i % k]
            rn = ring[(i + 1) % k]
            if ri == GHOST or rn == GHOST:
                continue
            t = tof[ri]
            for c in range(3 * t, 3 * t + 3):
                if tri[c] == R:
                    tri[c] = C
            vtri[R].discard(t)
            vtri[C].add(t)
        # The new triangles (P, C, a) and (C, P, b), SPEC §7.4, for real wings.
        for wing, corners in ((a, (R, C, a)), (b, (C, R, b))):
            if wing == GHOST:
                continue
            t = self.T
            tri.extend(corners)
            for v in corners:
                vtri[v].add(t)
            self.T += 1
        self.pos[R] = P
        self.pos.append(Cp)
        deficit[R] = dP
        deficit.append(dC)
        if self.every:  # R's split-history bit (3.10)
            self.split.add(R)
        self.V += 1


def main():
    data = sys.stdin.buffer.read()
    out = []
    dec = Decoder(data, out)
    try:
        dec.run()
        out.append("ok")
    except Fail as f:
        out.append("error " + f.cls)
    except RecursionError:
        out.append("error malformed")
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
