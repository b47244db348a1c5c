"""A second decoder of the facemime bitstream, written from ``docs/bitstream.md`` alone (no
loss handling: it decodes an undamaged stream), to check that the document says enough."""

import struct
import zlib

D = (3764, 6909, 11147, 16245, 21852, 27600, 33170, 38337, 42966, 47001, 50443, 53330, 55718, 57674, 59263, 60544)
M32 = 0xFFFFFFFF


#: The largest payload of each kind: header, actor, intra and inter packets, appearance.
LIMITS = {1: 1 << 20, 2: 1 << 26, 3: 1 << 16, 4: 1 << 16, 5: 1 << 20}


def chunks(data: bytes):
    """(kind, frames, seq, payload) of each chunk (the stream must be undamaged: anything that
    is not a chunk fails an assertion)."""
    at = 0
    while at < len(data):
        tag, seq = data[at], struct.unpack_from("<H", data, at + 1)[0]
        kind = tag >> 5
        assert kind in LIMITS and (kind in (3, 4) or tag & 31 == 0)
        length, shift, pos = 0, 0, at + 3
        while True:
            b = data[pos]
            pos += 1
            length |= (b & 0x7F) << shift
            shift += 7
            if not b & 0x80:
                break
            assert shift < 28
        assert length <= LIMITS[kind]
        end = pos + length
        assert zlib.crc32(data[at:end]) == struct.unpack_from("<I", data, end)[0]
        yield kind, (tag & 31) + 1, seq, data[pos:end]
        at = end + 4


def header(p: bytes) -> dict:
    assert p[:4] == b"FMST" and p[4] in (1, 2)
    num, den, w, h = struct.unpack_from("<IIHH", p, 5)
    at = 17 + 8
    frames, keyframes, n = struct.unpack_from("<BHB", p, at)
    at += 4
    params = [struct.unpack_from("<fiB", p, at + 9 * i) for i in range(n)]
    at += 9 * n
    extras = []
    if p[4] == 2:
        extras = list(p[at + 1 : at + 1 + p[at]])
        at += 1 + p[at]
        assert len(extras) <= n - 6 and 0 not in extras and len(set(extras)) == len(extras)
    (rows,) = struct.unpack_from("<H", p, at)
    at += 2 + 2 * (n - 6 - len(extras)) * rows + 32
    assert at + 1 == len(p)
    return {
        "fps": (num, den),
        "size": (w, h),
        "P": frames,
        "K": keyframes,
        "steps": [x[0] for x in params],
        "references": [x[1] for x in params],
        "classes": [x[2] for x in params],
        "extras": extras,
        "carried": p[at],
    }


def table(freq: list[int]) -> list[int]:
    n, total = len(freq), sum(freq)
    p = [1 + f * (4096 - n) // total for f in freq]
    p[freq.index(max(freq))] += 4096 - sum(p)
    cdf = [0]
    for x in p:
        cdf.append(cdf[-1] + x)
    return cdf


def uniform(bits: int) -> list[int]:
    return [s << (12 - bits) for s in range((1 << bits) + 1)]


def starting(c: int) -> list[int]:
    f = [4096]
    for _ in range(12):
        f.append(max(1, f[-1] * D[c] >> 16))
    return f[:0:-1] + f + [max(1, f[12])]


class Context:
    def __init__(self, freq: list[int]):
        self.freq, self.step = list(freq), max(1, sum(freq) >> 4)
        self.cdf = table(self.freq)

    def update(self, s: int) -> None:
        self.freq[s] += self.step
        if sum(self.freq) > 1 << 24:
            self.freq = [(f + 1) >> 1 for f in self.freq]
        self.cdf = table(self.freq)


class Range:
    def __init__(self, payload: bytes):
        self.words = list(struct.unpack(f"<{len(payload) // 2}H", payload))
        self.next = 2
        w = self.words + [0, 0]
        self.lower, self.range = 0, M32
        self.point = (w[0] << 16) | w[1] if len(self.words) >= 2 else (w[0] << 16 if self.words else 0)

    def symbol(self, cdf: list[int]) -> int:
        scale = self.range >> 12
        quantile = ((self.point - self.lower) & M32) // scale
        assert quantile < 4096
        s = max(i for i in range(len(cdf) - 1) if cdf[i] <= quantile)
        self.lower = (self.lower + scale * cdf[s]) & M32
        self.range = scale * (cdf[s + 1] - cdf[s])
        if self.range < 1 << 16:
            self.lower = (self.lower << 16) & M32
            self.range <<= 16
            w = self.words[self.next] if self.next < len(self.words) else 0
            self.next += 1
            self.point = ((self.point << 16) | w) & M32
        return s

    def value(self, cdf: list[int]) -> tuple[int, int]:
        s = self.symbol(cdf)
        if s != 25:
            return s - 12, s
        negative = self.symbol(uniform(1)) == 1
        n = self.symbol(uniform(5))
        m, left = (1 if n else 0), max(n - 1, 0)
        while left:
            b = min(12, left)
            m = (m << b) | self.symbol(uniform(b))
            left -= b
        return (-(13 + m) if negative else 13 + m), s


def decode(data: bytes, appearance: list | None = None) -> list[dict]:
    """Every frame of an undamaged stream: index, face, lost, values (floats, the extras last;
    the header's ``extras`` name their kinds), and with extras ``look``: the look's six values
    (kinds 1-6; an absent kind is 0, an unknown one ignored). ``appearance``: a list that gets
    (frames before it, payload) of each appearance chunk after a header whose payload holds at
    least its 8 bytes of frame and place."""
    frames, h, state = [], None, None
    for kind, count, seq, payload in chunks(data):
        if kind == 1:
            h = header(payload)
        if kind == 5 and h is not None and len(payload) >= 8 and appearance is not None:
            appearance.append((len(frames), payload))
        if kind not in (3, 4):
            continue
        if kind == 3:
            state = {
                "values": [Context(starting(c)) for c in h["classes"]],
                "flags": Context([496 if s == 1 else 16 for s in range(32)]),
                "pred": None,
            }
        coder = Range(payload)
        for j in range(count):
            flags = coder.symbol(state["flags"].cdf)
            state["flags"].update(flags)
            entry = {"index": seq * h["P"] + j, "face": bool(flags & 1), "lost": flags >> 1}
            if flags & 1:
                q = []
                for i, ctx in enumerate(state["values"]):
                    if state["pred"] is None:
                        q.append(h["references"][i] + coder.value(table(starting(15)))[0])
                    else:
                        v, s = coder.value(ctx.cdf)
                        ctx.update(s)
                        q.append(state["pred"][i] + v)
                state["pred"] = q
                entry["values"] = [float(x) * float(step) for x, step in zip(q, h["steps"])]
                if h["extras"]:
                    look = [0.0] * 6
                    for kind, value in zip(h["extras"], entry["values"][len(q) - len(h["extras"]) :]):
                        if 1 <= kind <= 6:
                            look[kind - 1] = value
                    entry["look"] = look
            frames.append(entry)
    return frames
