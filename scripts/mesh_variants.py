#!/usr/bin/env python3
"""Writes split-vertex variants of a triangle OBJ (positions and faces only) that render the same
image as the original: the probes of split-vertex vertex derivatives (docs/design-notes.md).

  mesh_variants.py IN.obj OUT_DIR [--normalize]

OUT_DIR/welded.obj  the mesh as read (normalized like `sft synth` with --normalize: bounding-box
                    centre at the origin, diagonal 1)
OUT_DIR/soup.obj    every face with its own three vertices
OUT_DIR/flipped.obj every other face with reversed winding (vertices shared)
OUT_DIR/seam.obj    the faces whose centroid has x > 0 get their own copies of the vertices they
                    share with faces on the other side (one closed position seam)
"""
import math
import os
import sys


def read_obj(path):
    positions, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == 'v':
                positions.append([float(x) for x in parts[1:4]])
            elif parts[0] == 'f':
                idx = [int(p.split('/')[0]) - 1 for p in parts[1:]]
                for k in range(1, len(idx) - 1):
                    faces.append([idx[0], idx[k], idx[k + 1]])
    return positions, faces


def write_obj(path, positions, faces):
    with open(path, 'w') as f:
        for p in positions:
            f.write('v %r %r %r\n' % tuple(p))
        for face in faces:
            f.write('f %d %d %d\n' % tuple(i + 1 for i in face))


def main():
    src, out = sys.argv[1], sys.argv[2]
    positions, faces = read_obj(src)
    if '--normalize' in sys.argv:
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        centre = [0.5 * (lo[k] + hi[k]) for k in range(3)]
        diagonal = math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3)))
        positions = [[(p[k] - centre[k]) / diagonal for k in range(3)] for p in positions]
    os.makedirs(out, exist_ok=True)
    write_obj(os.path.join(out, 'welded.obj'), positions, faces)
    soup_positions = [positions[i] for face in faces for i in face]
    write_obj(os.path.join(out, 'soup.obj'), soup_positions,
              [[3 * f, 3 * f + 1, 3 * f + 2] for f in range(len(faces))])
    write_obj(os.path.join(out, 'flipped.obj'), positions,
              [face[::-1] if f % 2 else face for f, face in enumerate(faces)])
    right = [sum(positions[i][0] for i in face) > 0 for face in faces]
    used_left = set(i for face, r in zip(faces, right) if not r for i in face)
    seam_positions = list(positions)
    copy = {}
    seam_faces = []
    for face, r in zip(faces, right):
        if r:
            new_face = []
            for i in face:
                if i in used_left:
                    if i not in copy:
                        copy[i] = len(seam_positions)
                        seam_positions.append(positions[i])
                    i = copy[i]
                new_face.append(i)
            face = new_face
        seam_faces.append(face)
    write_obj(os.path.join(out, 'seam.obj'), seam_positions, seam_faces)
    print('%d faces; soup %d vertices; seam %d split vertices' %
          (len(faces), len(soup_positions), len(copy)))


if __name__ == '__main__':
    main()
