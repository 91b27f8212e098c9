#!/usr/bin/env python3
"""Pose-refinement measurements (docs/design-notes.md, "Camera pose refinement").

  perturb_poses.py perturb DATASET OUT --degrees 0.5 --translation 0.005 [--seed 1]
      Copies DATASET's scene.json to OUT/scene.json (with symlinks to its images, masks and gt/)
      with every view's cam_from_world but view 0's (the fit's gauge) turned by --degrees about a
      random axis and shifted by --translation scene units in a random direction, both applied on
      the left (in the camera frame), as sft's pose corrections are.
  perturb_poses.py score DATASET PERTURBED [RUN]
      The mean and largest rotation error (degrees) and mean camera-centre error of PERTURBED's
      poses against DATASET's, corrected by RUN/poses.json when given, and the mean reprojection
      error (pixels) of DATASET's true mesh's vertices (ground_truth.mesh, a PLY with float x y z
      first; pinhole intrinsics fx fy cx cy), which a rotation and translation that orbit the
      object change little.

Standard library only (no NumPy).
"""
import argparse
import json
import math
import os
import random
import struct


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def qrot(q, v):
    w, x, y, z = qmul(qmul(q, [0.0] + list(v)), [q[0], -q[1], -q[2], -q[3]])
    return [x, y, z]


def qexp(theta):
    a = math.sqrt(sum(t * t for t in theta))
    if a < 1e-15:
        return [1.0, 0.0, 0.0, 0.0]
    s = math.sin(a / 2) / a
    return [math.cos(a / 2)] + [s * t for t in theta]


def angle_deg(a, b):
    d = abs(sum(x * y for x, y in zip(a, b)))
    return 2 * math.degrees(math.acos(min(1.0, d)))


def left(pose, theta, tau):
    """exp(δ)·pose for δ = (theta, tau)."""
    q = qexp(theta)
    t = qrot(q, pose["translation"])
    return {"rotation": qmul(q, pose["rotation"]),
            "translation": [t[i] + tau[i] for i in range(3)]}


def centre(pose):
    """The camera centre −Rᵀt in the world."""
    q = pose["rotation"]
    c = qrot([q[0], -q[1], -q[2], -q[3]], pose["translation"])
    return [-x for x in c]


def random_unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-6:
            return [x / n for x in v]


def perturb(args):
    with open(os.path.join(args.dataset, "scene.json")) as f:
        scene = json.load(f)
    rng = random.Random(args.seed)
    for i, view in enumerate(scene["views"]):
        if i == 0:
            continue
        theta = [math.radians(args.degrees) * x for x in random_unit(rng)]
        tau = [args.translation * x for x in random_unit(rng)]
        view["cam_from_world"] = left(view["cam_from_world"], theta, tau)
    os.makedirs(args.out, exist_ok=True)
    for name in os.listdir(args.dataset):
        if name != "scene.json" and not os.path.exists(os.path.join(args.out, name)):
            os.symlink(os.path.abspath(os.path.join(args.dataset, name)),
                       os.path.join(args.out, name))
    with open(os.path.join(args.out, "scene.json"), "w") as f:
        json.dump(scene, f, indent=1)


def ply_vertices(path):
    """The x y z of a PLY's vertices (ascii or binary little-endian, float x y z first)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").split("\n")
    count, props, binary = 0, [], "binary_little_endian" in header[1]
    in_vertex = False
    for line in header:
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            count, in_vertex = int(words[2]), True
        elif words[:1] == ["element"]:
            in_vertex = False
        elif in_vertex and words[:1] == ["property"]:
            props.append(words[1])
    if binary:
        sizes = {"float": 4, "double": 8, "uchar": 1, "int": 4, "uint": 4}
        stride = sum(sizes[t] for t in props)
        fmt = "<ddd" if props[0] == "double" else "<fff"
        return [struct.unpack_from(fmt, data, end + i * stride) for i in range(count)]
    lines = data[end:].decode("ascii").split("\n")
    return [tuple(float(x) for x in lines[i].split()[:3]) for i in range(count)]


def project(pose, camera, x):
    q = pose["rotation"]
    p = qrot(q, x)
    p = [p[i] + pose["translation"][i] for i in range(3)]
    fx, fy, cx, cy = camera["params"][:4]
    return fx * p[0] / p[2] + cx, fy * p[1] / p[2] + cy


def reprojection_px(scene, views, truth, dataset):
    """Mean pixel distance between the true mesh's vertices projected at both poses."""
    mesh = scene.get("ground_truth", {}).get("mesh")
    if not mesh or scene["cameras"][0]["model"] not in ("PINHOLE", "OPENCV"):
        return None
    points = ply_vertices(os.path.join(dataset, mesh))[::10]
    cameras = {c["id"]: c for c in scene["cameras"]}
    total, n = 0.0, 0
    for i, (a, b) in enumerate(zip(views, truth)):
        if i == 0:
            continue
        camera = cameras[b["camera"]]
        for x in points:
            u0, v0 = project(a["cam_from_world"], camera, x)
            u1, v1 = project(b["cam_from_world"], camera, x)
            total += math.hypot(u0 - u1, v0 - v1)
            n += 1
    return total / n


def score(args):
    with open(os.path.join(args.dataset, "scene.json")) as f:
        scene = json.load(f)
    truth = scene["views"]
    with open(os.path.join(args.perturbed, "scene.json")) as f:
        views = json.load(f)["views"]
    if args.run:
        with open(os.path.join(args.run, "poses.json")) as f:
            for entry in json.load(f)["views"]:
                v = entry["view"]
                views[v]["cam_from_world"] = left(views[v]["cam_from_world"], entry["rotation"],
                                                  entry["translation"])
    rot, trans = [], []
    for i, (a, b) in enumerate(zip(views, truth)):
        if i == 0:
            continue
        rot.append(angle_deg(a["cam_from_world"]["rotation"], b["cam_from_world"]["rotation"]))
        ca, cb = centre(a["cam_from_world"]), centre(b["cam_from_world"])
        trans.append(math.sqrt(sum((x - y) ** 2 for x, y in zip(ca, cb))))
    line = "rotation error: mean %.4f deg, max %.4f deg; camera centre error: mean %.5f" % (
        sum(rot) / len(rot), max(rot), sum(trans) / len(trans))
    px = reprojection_px(scene, views, truth, args.dataset)
    print(line + ("" if px is None else "; reprojection error: mean %.3f px" % px))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("perturb")
    p.add_argument("dataset")
    p.add_argument("out")
    p.add_argument("--degrees", type=float, default=0.5)
    p.add_argument("--translation", type=float, default=0.005)
    p.add_argument("--seed", type=int, default=1)
    s = sub.add_parser("score")
    s.add_argument("dataset")
    s.add_argument("perturbed")
    s.add_argument("run", nargs="?")
    args = parser.parse_args()
    perturb(args) if args.command == "perturb" else score(args)


if __name__ == "__main__":
    main()
