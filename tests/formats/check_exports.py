#!/usr/bin/env python3
"""Independent check of `mocap track --c3d/--trc` (standard library only).

The C3D reader below is written from the C3D format description (c3d.org user guide:
header block, parameter section of groups and parameters, floating-point 3D data when
POINT:SCALE < 0, residual word -1 for an invalid sample), not from mocap's writer. It
tracks a short simulated recording with `mocap track` and checks that
  * the C3D header and parameters agree (points, frames, rate, DATA_START, labels),
  * every labelled marker of markers.csv is in the C3D at its frame and label, equal
    within float precision, with a valid residual word; every other sample is invalid,
  * the TRC file carries the same labels, rate, frame count and values (empty cells
    exactly where markers.csv has no row),
  * an unwritable or full export file is a one-line error naming that file.
With --scene humanoid it tracks a few frames of the whole-body humanoid (71 markers) on
3 cameras, its targets.yaml preceded by --extra-bodies bodies of 16 markers each that
are never in view, so that there are more than 255 labels: the C3D then continues
POINT:LABELS in POINT:LABELS2 (255 labels per parameter, the C3D convention for more than
255 points; DESCRIPTIONS likewise) and the humanoid's tracked markers land there.
Exits non-zero with a message on the first mismatch.
"""
import argparse
import csv
import math
import os
import random
import struct
import subprocess
import sys
import tempfile

BLOCK = 512


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def read_c3d(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 2 * BLOCK or len(data) % BLOCK != 0:
        fail("%s: size %d is not a whole number of 512-byte blocks" % (path, len(data)))
    param_block = data[0]
    if data[1] != 0x50:
        fail("header byte 2 is %d, not 0x50" % data[1])
    # Parameter section: its 4-byte header names the processor (84 = Intel, little-endian).
    p0 = (param_block - 1) * BLOCK
    n_param_blocks = data[p0 + 2]
    if data[p0 + 3] != 84:
        fail("processor type %d, expected 84 (Intel)" % data[p0 + 3])
    e = "<"
    words = struct.unpack_from(e + "256H", data, 0)
    hdr = {
        "points": words[1],
        "analog_per_frame": words[2],
        "first_frame": words[3],
        "last_frame": words[4],
        "scale": struct.unpack_from(e + "f", data, 12)[0],
        "data_start": words[8],
        "rate": struct.unpack_from(e + "f", data, 20)[0],
    }
    groups = {}  # id -> name
    params = {}  # (group id, name) -> value
    pos = p0 + 4
    end = p0 + n_param_blocks * BLOCK
    while pos < end:
        nlen = abs(struct.unpack_from("b", data, pos)[0])
        gid = struct.unpack_from("b", data, pos + 1)[0]
        if nlen == 0:
            break
        name = data[pos + 2:pos + 2 + nlen].decode("ascii")
        off_at = pos + 2 + nlen
        nxt = struct.unpack_from(e + "h", data, off_at)[0]
        if gid < 0:
            groups[-gid] = name
        else:
            q = off_at + 2
            etype = struct.unpack_from("b", data, q)[0]
            ndims = data[q + 1]
            dims = list(data[q + 2:q + 2 + ndims])
            q += 2 + ndims
            count = 1
            for d in dims:
                count *= d
            if etype == -1:
                raw = data[q:q + count].decode("ascii")
                if ndims <= 1:
                    value = raw.rstrip()
                else:
                    width = dims[0]
                    value = [raw[i:i + width].rstrip() for i in range(0, count, width)]
            else:
                size = {1: 1, 2: 2, 4: 4}[etype]
                fmt = {1: "B", 2: "h", 4: "f"}[etype]
                vals = list(struct.unpack_from(e + str(count) + fmt, data, q))
                value = vals if ndims > 0 else vals[0]
            params[(gid, name)] = value
        if nxt == 0:
            break
        pos = off_at + nxt
    named = {}
    for (gid, name), value in params.items():
        if gid not in groups:
            fail("parameter %s belongs to no group (id %d)" % (name, gid))
        named[groups[gid] + ":" + name] = value
    # 3D data: floating point when POINT:SCALE < 0; 4 words per point, no analog data.
    if named["POINT:SCALE"] >= 0 or hdr["scale"] >= 0:
        fail("POINT:SCALE must be negative (float data)")
    n = named["POINT:USED"]
    frames = hdr["last_frame"] - hdr["first_frame"] + 1
    start = (named["POINT:DATA_START"] - 1) * BLOCK
    samples = []
    for fi in range(frames):
        row = []
        for p in range(n):
            x, y, z, w = struct.unpack_from(e + "4f", data, start + 16 * (fi * n + p))
            row.append((x, y, z, w))
        samples.append(row)
    return hdr, named, samples


def string_list(par, key):
    """KEY, KEY2, KEY3, ... concatenated; each part holds at most 255 strings."""
    out = list(par[key])
    part = 2
    while "%s%d" % (key, part) in par:
        previous = par[key if part == 2 else "%s%d" % (key, part - 1)]
        if len(previous) != 255:
            fail("%s%d follows a part of %d strings (not 255)" % (key, part, len(previous)))
        out += par["%s%d" % (key, part)]
        part += 1
    return out


def check_c3d(path, markers, frames_csv, labels):
    hdr, par, samples = read_c3d(path)
    n = len(labels)
    if hdr["points"] != n or par["POINT:USED"] != n:
        fail("points %d / USED %d, expected %d" % (hdr["points"], par["POINT:USED"], n))
    if string_list(par, "POINT:LABELS") != labels:
        fail("labels %r, expected %r" % (string_list(par, "POINT:LABELS"), labels))
    if len(string_list(par, "POINT:DESCRIPTIONS")) != n:
        fail("%d descriptions for %d labels" % (len(string_list(par, "POINT:DESCRIPTIONS")), n))
    if (n > 255) != ("POINT:LABELS2" in par):
        fail("%d labels but POINT:LABELS2 %s" % (n, "present" if n <= 255 else "missing"))
    if par["POINT:UNITS"] != "mm":
        fail("units %r" % par["POINT:UNITS"])
    if hdr["data_start"] != par["POINT:DATA_START"]:
        fail("DATA_START header %d vs parameter %d" % (hdr["data_start"], par["POINT:DATA_START"]))
    if hdr["analog_per_frame"] != 0 or par["ANALOG:USED"] != 0:
        fail("unexpected analog data")
    nframes = len(frames_csv)
    if hdr["first_frame"] != frames_csv[0][0] + 1 or len(samples) != nframes:
        fail("frames %d..%d, expected %d frames from %d" % (hdr["first_frame"], hdr["last_frame"],
                                                            nframes, frames_csv[0][0] + 1))
    if (par["POINT:FRAMES"] & 0xFFFF) != nframes:
        fail("POINT:FRAMES %d, expected %d" % (par["POINT:FRAMES"], nframes))
    dt = (frames_csv[1][1] - frames_csv[0][1]) * 1e-9
    expected_rate = 1.0 / dt
    for rate in (hdr["rate"], par["POINT:RATE"]):
        if abs(rate - expected_rate) > 1e-3 * expected_rate:
            fail("rate %f, expected %f" % (rate, expected_rate))
    scale = abs(par["POINT:SCALE"])
    index_of_frame = {f: i for i, (f, _) in enumerate(frames_csv)}
    seen = set()
    for (frame, label), (x, y, z, res) in markers.items():
        i = index_of_frame[frame]
        p = labels.index(label)
        sx, sy, sz, w = samples[i][p]
        seen.add((i, p))
        for a, b in ((sx, x), (sy, y), (sz, z)):
            if abs(a - b) > 1e-6 * max(1.0, abs(b)) + 1e-5:
                fail("frame %d %s: C3D (%f,%f,%f) vs markers.csv (%f,%f,%f)" % (frame, label, sx, sy, sz, x, y, z))
        word = int(w)
        if word != w or word <= 0:
            fail("frame %d %s: residual word %r is not a valid sample" % (frame, label, w))
        if bin((word >> 8) & 0x7F).count("1") < 2:
            fail("frame %d %s: camera mask %#x has fewer than 2 cameras" % (frame, label, word >> 8))
        residual = (word & 0xFF) * scale
        if abs(residual - max(res, scale)) > scale / 2 + 1e-6 and not (res > 255 * scale):
            fail("frame %d %s: residual %f vs markers.csv %f" % (frame, label, residual, res))
    invalid = 0
    for i in range(len(samples)):
        for p in range(n):
            if (i, p) in seen:
                continue
            if samples[i][p][3] != -1.0:
                fail("frame index %d %s: no markers.csv row but residual word %r" % (i, labels[p], samples[i][p][3]))
            invalid += 1
    return invalid


def check_trc(path, markers, frames_csv, labels):
    with open(path) as f:
        lines = f.read().split("\n")
    if not lines[0].startswith("PathFileType\t4\t(X/Y/Z)"):
        fail("TRC line 1: %r" % lines[0])
    keys = lines[1].split("\t")
    vals = dict(zip(keys, lines[2].split("\t")))
    if int(vals["NumFrames"]) != len(frames_csv) or int(vals["NumMarkers"]) != len(labels):
        fail("TRC NumFrames/NumMarkers %s/%s" % (vals["NumFrames"], vals["NumMarkers"]))
    rate = 1.0 / ((frames_csv[1][1] - frames_csv[0][1]) * 1e-9)
    if abs(float(vals["DataRate"]) - rate) > 1e-3 * rate or vals["Units"] != "mm":
        fail("TRC DataRate/Units %s/%s" % (vals["DataRate"], vals["Units"]))
    names = lines[3].split("\t")
    if names[:2] != ["Frame#", "Time"] or [names[2 + 3 * i] for i in range(len(labels))] != labels:
        fail("TRC marker names %r" % names)
    rows = [l for l in lines[5:] if l.strip()]
    if len(rows) != len(frames_csv):
        fail("TRC has %d data rows, expected %d" % (len(rows), len(frames_csv)))
    for i, row in enumerate(rows):
        cells = row.split("\t")
        frame, t0 = frames_csv[i]
        if int(cells[0]) != frame + 1 or abs(float(cells[1]) - (t0 - frames_csv[0][1]) * 1e-9) > 1e-6:
            fail("TRC row %d: Frame#/Time %s/%s" % (i, cells[0], cells[1]))
        for p, label in enumerate(labels):
            xyz = cells[2 + 3 * p:5 + 3 * p]
            m = markers.get((frame, label))
            if m is None:
                if xyz != ["", "", ""]:
                    fail("TRC frame %d %s: expected empty cells, got %r" % (frame, label, xyz))
            elif any(abs(float(a) - b) > 1e-6 for a, b in zip(xyz, m[:3])):
                fail("TRC frame %d %s: %r vs %r" % (frame, label, xyz, m[:3]))


def one_line_error(cmd, name):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    lines = [l for l in r.stderr.splitlines() if l.strip() and "warning:" not in l]
    if r.returncode == 0 or len(lines) != 1 or name not in lines[0]:
        fail("expected a one-line error naming %s, got rc=%d stderr=%r" % (name, r.returncode, r.stderr))


def write_targets_with_extra_bodies(src, dst, extra):
    """targets.yaml of src preceded by `extra` bodies of 16 random markers (not in the scene)."""
    with open(src) as f:
        lines = f.read().split("\n")
    at = lines.index("bodies:") + 1
    added = []
    for b in range(extra):
        added += ["  - name: spare%02d" % b, "    markers:"]
        rng = random.Random(1000 + b)  # an irregular shape of its own per body
        pts = []
        while len(pts) < 16:  # markers at least 30 mm apart (balls of 14 mm)
            p = tuple(rng.uniform(-150.0, 150.0) for _ in range(3))
            if all(math.dist(p, q) >= 30.0 for q in pts):
                pts.append(p)
        added += ["      - [%.3f, %.3f, %.3f]" % p for p in pts]
    with open(dst, "w") as f:
        f.write("\n".join(lines[:at] + added + lines[at:]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mocap", required=True)
    ap.add_argument("--scene", default="limbs")
    ap.add_argument("--extra-bodies", type=int, default=0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="mocap_exports_") as tmp:
        rec = os.path.join(tmp, "rec")
        if args.scene == "humanoid":  # few frames and cameras: CI runs this under ASan
            sim = ["--scene", "humanoid", "--cameras", "3", "--frames", "3"]
        else:
            sim = ["--scene", args.scene, "--frames", "40", "--dropout", "0.08"]
        subprocess.run([args.mocap, "simulate", "--out", rec, "--fps", "120", "--threads", "1"] + sim,
                       check=True, capture_output=True, timeout=300)
        runs = [os.path.join(rec, "targets.yaml")]
        if args.extra_bodies > 0:  # the scene's own targets first, then behind the spares
            runs.append(os.path.join(tmp, "targets_extra.yaml"))
            write_targets_with_extra_bodies(runs[0], runs[1], args.extra_bodies)
        for targets in runs:
            check_run(args, rec, tmp, targets, extra=targets != runs[0])


def check_run(args, rec, tmp, targets, extra):
    out = os.path.join(tmp, "out")
    c3d, trc = os.path.join(tmp, "labelled.c3d"), os.path.join(tmp, "labelled.trc")
    track = [args.mocap, "track", rec, "--targets", targets, "--out", out, "--quiet"]
    subprocess.run(track + ["--c3d", c3d, "--trc", trc], check=True, timeout=120)
    with open(os.path.join(rec, "frames.csv")) as f:
        frames_csv = [(int(r["frame"]), int(r["timestamp_ns"])) for r in csv.DictReader(f)]
    markers = {}
    with open(os.path.join(out, "markers.csv")) as f:
        for r in csv.DictReader(f):
            label = "%s_m%s" % (r["body"], r["marker"])
            markers[(int(r["frame"]), label)] = (float(r["x"]), float(r["y"]), float(r["z"]),
                                                 float(r["residual_mm"]))
    labels = []
    body = None
    with open(targets) as f:  # names and marker counts, in order
        count = {}
        order = []
        for line in f:
            s = line.strip()
            if s.startswith("- name:"):
                body = s.split(":", 1)[1].strip().strip("'\"")
                order.append(body)
                count[body] = 0
            elif s.startswith("- [") and body is not None:
                count[body] += 1
        for b in order:
            labels += ["%s_m%d" % (b, m) for m in range(count[b])]
    if len(markers) < 20:
        fail("only %d labelled markers: the scene did not track" % len(markers))
    if args.scene == "humanoid" and not extra and len(labels) != 71:
        fail("the humanoid has %d labels, expected 71" % len(labels))
    if extra and not any(labels.index(l) >= 255 for (_, l) in markers):
        fail("no tracked marker has a label beyond the 255th: LABELS2 is not tested")
    invalid = check_c3d(c3d, markers, frames_csv, labels)
    if invalid == 0:
        fail("no invalid sample: the drop-outs did not test the invalid convention")
    check_trc(trc, markers, frames_csv, labels)
    if extra:  # the write errors do not depend on the targets: checked once
        print("ok: %d labelled samples, %d invalid, %d labels, %d frames" % (len(markers), invalid,
                                                                               len(labels), len(frames_csv)))
        return
    one_line_error(track + ["--c3d", os.path.join(tmp, "no", "such", "dir.c3d")], "dir.c3d")
    if os.path.exists("/dev/full"):
        one_line_error(track + ["--trc", "/dev/full"], "/dev/full")
        one_line_error(track + ["--c3d", "/dev/full"], "/dev/full")
    print("ok: %d labelled samples, %d invalid, %d labels, %d frames" % (len(markers), invalid,
                                                                           len(labels), len(frames_csv)))


if __name__ == "__main__":
    main()
