#!/usr/bin/env python3
"""A large E57 scan for timing vola's E57 reader (no E57 writer is packaged for Debian 12).

    bench/e57_scan.py OUT.e57 N

N random points in a 100 m cube (seeded): cartesianX/Y/Z as 32-bit ScaledIntegers of
1 mm, a 12-bit intensity and 8-bit colours, in data packets of 3600 records, laid in
1024-byte pages with their CRC-32C, as ASTM E2807 describes. Needs numpy.
"""
import struct, sys, numpy as np
n = int(sys.argv[2]); out = sys.argv[1]
rng = np.random.default_rng(1)
xyz = rng.uniform(-50, 50, size=(n, 3))
inten = rng.integers(0, 4096, n); rgb = rng.integers(0, 256, (n, 3))
def pack(raw, bits):
    # LSB-first bit packing of unsigned raw values
    raw = raw.astype(np.uint64)
    bitsarr = ((raw[:, None] >> np.arange(bits, dtype=np.uint64)) & 1).astype(np.uint8).reshape(-1)
    return np.packbits(bitsarr, bitorder='little').tobytes()
fields = []
for a in range(3):
    raw = np.round(xyz[:, a] / 0.001).astype(np.int64) - (-2**31)
    fields.append(('cartesian' + 'XYZ'[a], 'ScaledInteger', -2**31, 2**31 - 1, 0.001, 32, raw))
fields.append(('intensity', 'Integer', 0, 4095, 1, 12, inten))
for c, name in enumerate(['colorRed', 'colorGreen', 'colorBlue']):
    fields.append((name, 'Integer', 0, 255, 1, 8, rgb[:, c]))
per = 3600  # records a packet: 3600 x 16.5 bytes stays under the 64 KiB a packet may hold
body = bytearray()
streams = [pack(f[6], f[5]) for f in fields]
taken = [0] * len(fields)
npk = (n + per - 1) // per
for p in range(npk):
    last = min(n, (p + 1) * per)
    pieces = []
    for i, f in enumerate(fields):
        upto = len(streams[i]) if p + 1 == npk else last * f[5] // 8
        pieces.append(streams[i][taken[i]:upto]); taken[i] = upto
    pk = bytearray([1, 0, 0, 0]) + struct.pack('<H', len(fields)) + b''.join(struct.pack('<H', len(x)) for x in pieces) + b''.join(pieces)
    while len(pk) % 4: pk.append(0)
    pk[2:4] = struct.pack('<H', len(pk) - 1)
    body += pk
def phys(l): return l // 1020 * 1024 + l % 1020
logical = bytearray(48)
section = len(logical)
logical += bytes([1] + [0] * 7) + struct.pack('<QQQ', 32 + len(body), phys(section + 32), 0) + body
proto = ''.join(f'<{f[0]} type="{f[1]}" minimum="{f[2]}" maximum="{f[3]}"' + (f' scale="{f[4]}"' if f[1] == 'ScaledInteger' else '') + '/>' for f in fields)
xml = (f'<?xml version="1.0" encoding="UTF-8"?>\n<e57Root type="Structure" xmlns="http://www.astm.org/COMMIT/E57/2010-e57-v1.0"><data3D type="Vector"><vectorChild type="Structure"><name type="String">big</name><points type="CompressedVector" fileOffset="{phys(section)}" recordCount="{n}"><prototype type="Structure">{proto}</prototype><codecs type="Vector"/></points></vectorChild></data3D></e57Root>\n').encode()
xml_at = len(logical); logical += xml
while len(logical) % 1020: logical.append(0)
pages = len(logical) // 1020
logical[0:48] = b'ASTM-E57' + struct.pack('<IIQQQQ', 1, 0, pages * 1024, phys(xml_at), len(xml), 1024)
def crc32c(b):
    c = 0xFFFFFFFF
    for x in b: c = T[(c ^ x) & 0xFF] ^ (c >> 8)
    return c ^ 0xFFFFFFFF
T = []
for i in range(256):
    c = i
    for _ in range(8): c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
    T.append(c)
with open(out, 'wb') as f:
    for p in range(pages):
        page = bytes(logical[p * 1020:(p + 1) * 1020])
        f.write(page + struct.pack('>I', crc32c(page)))
