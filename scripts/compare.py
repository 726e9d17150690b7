#!/usr/bin/env python3
"""ballpit against Rapier on the same scenes: builds both, runs both, prints one markdown table.

Usage: scripts/compare.py [--quick]

Scenes are made by `ballpit bench ... --steps 0 --dump scene.csv`, so both engines step the very
same spheres. Each run is one process printing one JSON line; a run that fails becomes a row that
says why. The exact command lines are printed under the table. Budget: under 5 minutes on 2 cores
with the dependencies already compiled once (a cold build of rapier alone takes minutes).
"""

import json
import math
import os
import resource
import shlex
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PEER_DIR = os.path.join(ROOT, "peers", "rapier")
# BALLPIT_BIN points at another ballpit build to compare (the build step still runs).
BALLPIT = os.environ.get("BALLPIT_BIN") or os.path.join(ROOT, "target", "release", "ballpit")
PEER = os.path.join(PEER_DIR, "target", "release", "peer-rapier")
THREADS = os.cpu_count() or 2
DT = 1.0 / 60.0


def dense_radius(n, packing):
    """Radius giving `n` spheres the volume fraction `packing` of the unit cube."""
    return (packing * 3.0 / (4.0 * math.pi * n)) ** (1.0 / 3.0)


# name, scene flags for `ballpit bench` (its presets), steps, with Rapier's CCD as well.
SCENES = [
    ("dilute 1k (gas, packing 0.034)", ["--scene", "gas"], 1000, False),
    (
        "dilute 10k (gas, r 0.01, packing 0.042)",
        ["--scene", "gas", "--count", "10000", "--radius", "0.01"],
        150,
        False,
    ),
    (
        "dense 4k (packing 0.25)",
        ["--scene", "dense", "--count", "4000", "--radius", f"{dense_radius(4000, 0.25):.6f}"],
        300,
        False,
    ),
    # 200 spheres of radius 0.005 at 20 box lengths per second: 33 diameters per step at dt 1/60.
    ("fast projectiles 200", ["--scene", "projectiles"], 1500, True),
]
COMMON = ["--seed", "7", "--box", "1", "--dt", repr(DT)]
MODELS = ["discrete", "swept", "exact"]
THREADING = [("off", 1), ("pool", THREADS)]

commands = []


def run(cmd, timeout=120):
    """Runs one command, returns (json or None, error text)."""
    commands.append(shlex.join(cmd))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {timeout} s"
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # CPU seconds of the whole child (set-up included): unlike wall time, barely moved by other
    # work on a shared machine, so single-thread rows stay comparable across the run.
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        msg = (p.stderr.strip() or p.stdout.strip() or f"exit {p.returncode}").splitlines()[0]
        if "invalid value" in msg and "--model" in msg:
            msg = "model not in this build (`--model` refused it)"
        return None, msg[:100]
    try:
        out = json.loads(p.stdout.strip().splitlines()[-1])
        out["process_cpu_seconds"] = cpu
        return out, ""
    except (ValueError, IndexError):
        return None, "no JSON line in the output"


def build():
    t = time.monotonic()
    for cmd, cwd in (
        (["cargo", "build", "--release", "--quiet", "--bin", "ballpit"], ROOT),
        (["cargo", "build", "--release", "--quiet"], PEER_DIR),
    ):
        commands.append(f"(cd {os.path.relpath(cwd, ROOT) or '.'} && {shlex.join(cmd)})")
        subprocess.run(cmd, cwd=cwd, check=True)
    return time.monotonic() - t


def make_scene(flags, path):
    """`--steps 0 --dump` writes the start state; `--steps 1` is the fallback if 0 is refused."""
    for steps in ("0", "1"):
        out, err = run([BALLPIT, "bench", *flags, *COMMON, "--steps", steps, "--dump", path])
        if out is not None and os.path.exists(path):
            return steps, ""
    return None, err


def fmt_rate(x):
    return "n/a" if x is None else f"{x / 1e6:.3g} M"


def fmt_sci(x):
    if x is None:
        return "n/a"
    return "0" if x == 0 else f"{x:.1e}"


def cpu_rate(out):
    cpu = out and out.get("process_cpu_seconds")
    return out["n"] * out["steps"] / cpu if cpu else None


def row(scene, engine, threading, threads, out, err, ref, ref_cpu):
    if out is None:
        return f"| {scene} | {engine} | {threading} | {threads} | failed: {err} | | | | | | |"
    rate = out.get("sphere_steps_per_second")
    crate = cpu_rate(out)
    cratio = f"{crate / ref_cpu:.2f}x" if crate and ref_cpu else "n/a"
    escaped = out.get("escaped", "n/a")
    # The peer also says how deep: a count alone can't tell 1e-6 r inside a wall from tunnelling.
    depth = out.get("max_escape_rel")
    if escaped and depth is not None:
        escaped = f"{escaped} (≤ {depth:.1g} r)"
    ratio = f"{rate / ref:.2f}x" if rate and ref else "n/a"
    return (
        f"| {scene} | {engine} | {threading} | {threads} | {fmt_rate(rate)} | {ratio} | "
        f"{fmt_rate(crate)} | {cratio} | "
        f"{fmt_sci(out.get('energy_drift_rel'))} | {escaped} | "
        f"{fmt_sci(out.get('max_overlap_rel'))} |"
    )


def main():
    quick = "--quick" in sys.argv[1:]
    start = time.monotonic()
    load_start = os.getloadavg()[0]
    build_s = build()
    rows, notes = [], []
    with tempfile.TemporaryDirectory(prefix="ballpit-compare-") as tmp:
        for i, (name, flags, steps, with_ccd) in enumerate(SCENES):
            if quick:
                steps = max(1, steps // 10)
            csv = os.path.join(tmp, f"scene{i}.csv")
            how, err = make_scene(flags, csv)
            if how is None:
                rows.append(f"| {name} | scene | | | failed: {err} | | | | | | |")
                continue
            if how == "1":
                notes.append(f"{name}: `--steps 0` was refused, the scene is the state after 1 step")
            k = str(steps)
            peer = [PEER, csv, "--box", "1", "--dt", repr(DT), "--steps", k]
            rapier = {}
            for variant in ([], ["--ccd"]) if with_ccd else ([],):
                for label, t in (("single", 1), ("parallel", THREADS)):
                    rapier[(bool(variant), label)] = run([*peer, *variant, "--threads", str(t)])
            # Like for like: on projectiles ballpit claims no tunnelling, so it meets Rapier's CCD.
            ref_out = rapier[(with_ccd, "single")][0]
            ref = ref_out and ref_out.get("sphere_steps_per_second")
            ref_cpu = cpu_rate(ref_out)
            for model in MODELS:
                for threading, t in THREADING:
                    out, err = run(
                        [BALLPIT, "bench", "--scene", csv, *COMMON, "--model", model,
                         "--threading", threading, "--threads", str(t), "--steps", k]
                    )
                    rows.append(
                        row(name, f"ballpit {model}", threading, t, out, err, ref, ref_cpu)
                    )
            for (ccd, label), (out, err) in rapier.items():
                t = 1 if label == "single" else THREADS
                engine = "rapier + CCD" if ccd else "rapier"
                rows.append(row(name, engine, label, t, out, err, ref, ref_cpu))
    total = time.monotonic() - start
    load_end = os.getloadavg()[0]

    print(
        "| scene | engine / model | threading | threads | sphere-steps/s | × Rapier single "
        "| per CPU-second | × Rapier single (CPU) | energy drift | escaped | deepest overlap |"
    )
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    print("\n".join(rows))
    print()
    print(
        f"dt = 1/60 s, box 1, seed 7. `× Rapier single` divides by Rapier single-thread on the same "
        f"scene (on fast projectiles: Rapier single with CCD), by wall time of the stepping; `per CPU-second` divides the sphere-steps by the CPU time of the whole process (user + system, set-up included), which other load on the machine barely moves. Energy drift = |E_end − E_start| / "
        f"E_start; escaped = centres outside [r, L−r] by more than 1e-9 L (for Rapier, with the deepest as a fraction of the radius); deepest overlap = deepest "
        f"pair overlap / smaller radius at the end. Rapier 0.36.1 (f32, rayon `parallel` feature, "
        f"length_unit = mean diameter); one run each on a {THREADS}-core machine, 1-minute load average {load_start:.1f} at the start "
        f"and {load_end:.1f} at the end (other work competes for the cores: compare within a scene)."
    )
    for n in notes:
        print(f"- {n}")
    print(f"\nBuilds {build_s:.0f} s, total {total:.0f} s. Commands, in order:\n")
    print("```")
    print("\n".join(commands))
    print("```")


if __name__ == "__main__":
    main()
