#!/usr/bin/env python3
"""Draws a binary STL written by `sdfc mesh` as a PNG: a plain z-buffer rasteriser in numpy,
flat-shaded by each triangle's own normal (so the facets show), with the triangle edges
drawn darker when --edges is given. Used for the picture in docs/mesh.md.

usage: mesh_picture.py MESH.stl OUT.png [--size WxH] [--eye X,Y,Z] [--at X,Y,Z] [--fov DEG] [--edges]
"""
import struct, sys, zlib
import numpy as np

def read_stl(path):
    data = open(path, "rb").read()
    n = struct.unpack("<I", data[80:84])[0]
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    return np.frombuffer(data[84:], dtype=rec, count=n)["v"].astype(np.float64)

def write_png(path, rgb):
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)

def main():
    args = sys.argv[1:]
    opt = lambda k, d: args[args.index(k) + 1] if k in args else d
    w, h = map(int, opt("--size", "800x600").split("x"))
    eye = np.array(list(map(float, opt("--eye", "1.6,1.4,-2.6").split(","))))
    at = np.array(list(map(float, opt("--at", "0,-0.1,0").split(","))))
    tris = read_stl(args[0])
    fwd = at - eye; fwd /= np.linalg.norm(fwd)
    right = np.cross(np.array([0, 1.0, 0]), fwd); right /= np.linalg.norm(right)
    up = np.cross(fwd, right)
    rel = tris - eye
    cam = np.stack([rel @ right, rel @ up, rel @ fwd], axis=-1)
    f = 1.0 / np.tan(np.radians(float(opt("--fov", "45"))) / 2)
    sx = (cam[..., 0] / cam[..., 2] * f * h / 2 + w / 2)
    sy = (-cam[..., 1] / cam[..., 2] * f * h / 2 + h / 2)
    z = cam[..., 2]
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-300
    light = -np.array([0.5, -1.0, 0.4]); light /= np.linalg.norm(light)
    shade = 0.15 + 0.85 * np.clip(n @ light, 0, 1)
    facing = (n * (tris.mean(axis=1) - eye)).sum(axis=1) < 0
    zbuf = np.full((h, w), np.inf)
    img = np.zeros((h, w, 3))
    img[:] = [0.93, 0.94, 0.96]
    edges = "--edges" in args
    base = np.array([0.78, 0.62, 0.48])
    for t in np.nonzero(facing)[0]:
        xs, ys, zs = sx[t], sy[t], z[t]
        x0, x1 = max(int(np.floor(xs.min())), 0), min(int(np.ceil(xs.max())), w - 1)
        y0, y1 = max(int(np.floor(ys.min())), 0), min(int(np.ceil(ys.max())), h - 1)
        if x0 > x1 or y0 > y1:
            continue
        px, py = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
        d = (ys[1] - ys[2]) * (xs[0] - xs[2]) + (xs[2] - xs[1]) * (ys[0] - ys[2])
        if d == 0:
            continue
        l0 = ((ys[1] - ys[2]) * (px - xs[2]) + (xs[2] - xs[1]) * (py - ys[2])) / d
        l1 = ((ys[2] - ys[0]) * (px - xs[2]) + (xs[0] - xs[2]) * (py - ys[2])) / d
        l2 = 1 - l0 - l1
        inside = (l0 >= -1e-6) & (l1 >= -1e-6) & (l2 >= -1e-6)
        depth = l0 * zs[0] + l1 * zs[1] + l2 * zs[2]
        sub = zbuf[y0:y1 + 1, x0:x1 + 1]
        win = inside & (depth < sub)
        sub[win] = depth[win]
        c = base * shade[t]
        if edges:
            near = np.minimum(np.minimum(l0, l1), l2) < 0.06
            col = np.where(near[..., None], c * 0.55, c)
        else:
            col = np.broadcast_to(c, l0.shape + (3,))
        img[y0:y1 + 1, x0:x1 + 1][win] = col[win]
    write_png(args[1], (np.clip(img, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8))

main()
