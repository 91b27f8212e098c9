#!/usr/bin/env python3
"""Writes the COLMAP text model of data/colmap/spot/ from an `sft synth` dataset.

COLMAP 3.8 on CPU could not register the synthetic spot in front of a distant probe (320x320,
24 views: 142 SIFT features per image, "No good initial image pair"; with relaxed initialisation
thresholds 2 images and 14 points), so the fixture model is written from the truth instead
(docs/import.md): the synth cameras, the spot mesh's vertices that face a camera and project into
its image (with 0.3 px Gaussian noise on the observations), and 150 background points on a sphere
of radius 4 around the object (the "environment" that COLMAP would also reconstruct; they test
the normalisation without masks). Everything is mapped by a fixed similarity (scale 3.7, a
rotation, a translation) so that COLMAP's frame differs from sft's. `colmap model_converter`
then writes the binary model (and the text model again), so both stored versions are written by
COLMAP itself.

Usage: make_colmap_fixture.py SYNTH_DATASET SPOT_OBJ OUT_TEXT_MODEL_DIR
(SYNTH_DATASET made by `sft synth --mesh spot_triangulated.obj --up-axis y --res 320 ...`).
"""
import json
import math
import os
import random
import sys


def quat_to_matrix(q):
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def matrix_to_quat(m):
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return [0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0] * 4
    q[0] = (m[k][j] - m[j][k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (m[j][i] + m[i][j]) / s
    q[1 + k] = (m[k][i] + m[i][k]) / s
    return q


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def transpose(m):
    return [[m[j][i] for j in range(3)] for i in range(3)]


def read_spot(path):
    """Vertices and vertex normals of the OBJ as `sft synth --up-axis y` places it."""
    verts, faces = [], []
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == 'v':
            x, y, z = map(float, t[1:4])
            verts.append([x, -z, y])
        elif t[0] == 'f':
            faces.append([int(s.split('/')[0]) - 1 for s in t[1:4]])
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    c = [(lo[i] + hi[i]) / 2 for i in range(3)]
    d = math.sqrt(sum((hi[i] - lo[i]) ** 2 for i in range(3)))
    verts = [[(v[i] - c[i]) / d for i in range(3)] for v in verts]
    normals = [[0.0, 0.0, 0.0] for _ in verts]
    for f in faces:
        a, b, cc = (verts[i] for i in f)
        u = [b[i] - a[i] for i in range(3)]
        w = [cc[i] - a[i] for i in range(3)]
        n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        for i in f:
            normals[i] = [normals[i][k] + n[k] for k in range(3)]
    return verts, normals


def main():
    synth, obj, out = sys.argv[1:4]
    rng = random.Random(12)
    scene = json.load(open(os.path.join(synth, 'scene.json')))
    cam = scene['cameras'][0]
    fx, fy, cx, cy = cam['params']
    width, height = cam['width'], cam['height']
    verts, normals = read_spot(obj)
    # Every 4th vertex is enough for a fixture (~730 object points).
    points = [(verts[i], normals[i], (200, 200, 200)) for i in range(0, len(verts), 4)]
    for _ in range(150):
        z = rng.uniform(-1, 1)
        phi = rng.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        p = [4 * r * math.cos(phi), 4 * r * math.sin(phi), 4 * z]
        points.append((p, None, (90, 90, 90)))

    # source_from_sft: p_colmap = s * R * p + t.
    s = 3.7
    R = quat_to_matrix([math.cos(0.4), math.sin(0.4) * 0.48, math.sin(0.4) * 0.6,
                        math.sin(0.4) * 0.64])
    t = [1.5, -2.0, 0.75]

    images = []
    observations = {k: [] for k in range(len(points))}
    for v, view in enumerate(scene['views']):
        q = view['cam_from_world']['rotation']
        Rc = quat_to_matrix(q)
        tc = view['cam_from_world']['translation']
        centre = [-x for x in apply(transpose(Rc), tc)]
        pts2d = []
        for k, (p, n, _) in enumerate(points):
            pc = [a + b for a, b in zip(apply(Rc, p), tc)]
            if pc[2] <= 0:
                continue
            if n is not None:
                to_cam = [centre[i] - p[i] for i in range(3)]
                if sum(n[i] * to_cam[i] for i in range(3)) <= 0:
                    continue
            x = fx * pc[0] / pc[2] + cx + rng.gauss(0, 0.3)
            y = fy * pc[1] / pc[2] + cy + rng.gauss(0, 0.3)
            if not (0 <= x < width and 0 <= y < height):
                continue
            observations[k].append((v + 1, len(pts2d)))
            pts2d.append((x, y, k))
        # cam_from_colmap: R_c R^T / s on (p_colmap - t), so rotation Rc R^T and translation
        # s * tc - Rc R^T t (camera frame scaled with the world).
        Rn = mul(Rc, transpose(R))
        tn = [s * tc[i] - apply(Rn, t)[i] for i in range(3)]
        ext = 'png' if v == len(scene['views']) - 1 else 'jpg'
        images.append((v + 1, matrix_to_quat(Rn), tn, '%03d.%s' % (v, ext), pts2d))

    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, 'cameras.txt'), 'w') as f:
        f.write('1 PINHOLE %d %d %.17g %.17g %.17g %.17g\n' % (width, height, fx, fy, cx, cy))
    with open(os.path.join(out, 'images.txt'), 'w') as f:
        for iid, qn, tn, name, pts2d in images:
            f.write('%d %s %s 1 %s\n' % (iid, ' '.join('%.17g' % x for x in qn),
                                          ' '.join('%.17g' % x for x in tn), name))
            f.write(' '.join('%.17g %.17g %d' % (x, y, k + 1 if len(observations[k]) >= 2 else -1)
                             for x, y, k in pts2d) + '\n')
    with open(os.path.join(out, 'points3D.txt'), 'w') as f:
        for k, (p, _, rgb) in enumerate(points):
            if len(observations[k]) < 2:
                continue
            pc = [s * a + b for a, b in zip(apply(R, p), t)]
            track = ' '.join('%d %d' % o for o in observations[k])
            f.write('%d %.17g %.17g %.17g %d %d %d 0.3 %s\n' % ((k + 1,) + tuple(pc) + rgb + (track,)))


if __name__ == '__main__':
    main()
