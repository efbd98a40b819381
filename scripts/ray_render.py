#!/usr/bin/env python3
"""Render with rastergi on a Ray cluster: one image split into seed shards, or a camera path
split into frames, over the cluster's GPU workers.

Each task runs `rastergi render ... --checkpoint FILE` in a working directory that every node
sees (a shared file system: NFS, a mounted bucket; on one machine, any directory). A task whose
worker is lost (a node gone, a process killed) is retried by Ray (`--retries`) and resumes from
the shard's last checkpoint (`--resume`): the finished shard is the same, bit for bit, as one
that was never interrupted. The shards of an image are merged with `rastergi merge`, each
weighted by its iterations.

One image, 8 shards of 256 iterations, seeds 1..8:

    python3 scripts/ray_render.py cornell --shards 8 --iterations 256 --out cornell.exr \\
        --work-dir /shared/run1 -- --width 1024 --height 1024

Frames along keyframed cameras (FILE.json: {"frames": 120, "keys": [{"t": 0, "eye": [x, y, z],
"target": [x, y, z], "up": [0, 1, 0], "fov": 40}, ...]}, linear between keys):

    python3 scripts/ray_render.py scene.gltf --camera-path path.json --iterations 128 \\
        --out 'frames/frame_{:04d}.png' --work-dir /shared/run2

On a cluster: `ray start --head` on one node, `ray start --address HEAD:6379` on the others,
then this script with `--address auto` on the head (docs/user-guide.md, "Long renders"). Without
--address, Ray starts a local cluster of this machine's CPUs and GPUs.
"""

import argparse
import ctypes
import json
import os
import shutil
import signal
import subprocess
import sys
import time

# Ray is imported in main(): --help works without it.


def die_with_parent():
    """In the child of a Ray task: die with the task's worker (Linux), so a killed worker does
    not leave its render running and writing the shard's checkpoint."""
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def run_task(rastergi, args, work_dir, name, total, out):
    """Runs one shard or frame into the image `out`: `args` are its render arguments without
    --out/--checkpoint; resumes from the checkpoint a lost attempt left. Returns (name,
    iterations, attempt)."""
    ckpt = os.path.join(work_dir, name + ".ckpt")
    attempt_file = os.path.join(work_dir, name + ".attempts")
    attempt = 1
    if os.path.exists(attempt_file):
        with open(attempt_file) as f:
            attempt = int(f.read().strip() or "0") + 1
    with open(attempt_file, "w") as f:
        f.write(str(attempt))
    # The worker's pid, for the tests that kill it.
    with open(os.path.join(work_dir, name + ".pid"), "w") as f:
        f.write(str(os.getpid()))
    cmd = [rastergi, "render"] + args + ["--iterations", str(total), "--out", out, "--checkpoint", ckpt]
    if os.path.exists(ckpt):
        cmd += ["--resume", ckpt]
        print(f"{name}: attempt {attempt} resumes from its checkpoint", flush=True)
    done = subprocess.run(cmd, preexec_fn=die_with_parent, capture_output=True, text=True)
    if done.returncode != 0:
        lines = [l for l in done.stderr.splitlines() if "XDG_RUNTIME_DIR" not in l]
        raise RuntimeError(f"{name}: rastergi exited with {done.returncode}: {' '.join(lines)[-500:]}")
    return name, total, attempt


def lerp(a, b, t):
    return [x + (y - x) * t for x, y in zip(a, b)]


def camera_frames(path):
    """The cameras of a camera-path file, one per frame, linear between the keyframes."""
    with open(path) as f:
        spec = json.load(f)
    keys = sorted(spec["keys"], key=lambda k: k["t"])
    if not keys:
        sys.exit(f"error: {path}: no keys")
    frames = int(spec.get("frames", len(keys)))
    if frames < 1:
        sys.exit(f"error: {path}: frames must be at least 1")
    t0, t1 = keys[0]["t"], keys[-1]["t"]
    cams = []
    for i in range(frames):
        t = t0 if frames == 1 else t0 + (t1 - t0) * i / (frames - 1)
        k = max(j for j in range(len(keys)) if keys[j]["t"] <= t)
        a, b = keys[k], keys[min(k + 1, len(keys) - 1)]
        s = 0.0 if b["t"] == a["t"] else (t - a["t"]) / (b["t"] - a["t"])
        cam = {"eye": lerp(a["eye"], b["eye"], s), "target": lerp(a["target"], b["target"], s)}
        cam["up"] = lerp(a.get("up", [0, 1, 0]), b.get("up", [0, 1, 0]), s)
        if "fov" in a:
            cam["fov"] = a["fov"] + (b.get("fov", a["fov"]) - a["fov"]) * s
        cams.append(cam)
    return cams


def vec(v):
    return ",".join(f"{x:.9g}" for x in v)


def main():
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Arguments after -- go to every `rastergi render` unchanged.")
    p.add_argument("scene", help="the scene (a file every node can read, or a built-in name)")
    p.add_argument("--out", required=True,
                   help="the merged image (.exr/.png); with --camera-path a pattern such as 'f_{:04d}.png'")
    p.add_argument("--iterations", type=int, required=True, help="iterations per shard (or per frame)")
    p.add_argument("--shards", type=int, default=2, help="seed shards of the image (seeds --seed … --seed + N − 1)")
    p.add_argument("--seed", type=int, default=1, help="the first shard's seed")
    p.add_argument("--camera-path", help="render a frame sequence along these keyframed cameras instead")
    p.add_argument("--work-dir", required=True, help="shards' checkpoints and images; shared by every node")
    p.add_argument("--address", help="the Ray cluster to join (e.g. auto); default: a local one")
    p.add_argument("--gpus-per-task", type=float, default=1.0,
                   help="GPUs each render takes (0 renders on CPU workers: lavapipe)")
    p.add_argument("--retries", type=int, default=3, help="attempts after a lost worker, per task")
    p.add_argument("--checkpoint-every", type=float, default=30.0, help="seconds between a shard's checkpoints")
    p.add_argument("--rastergi", default=None, help="the rastergi binary (default: on PATH, or target/release)")
    argv = sys.argv[1:]
    render_args = argv[argv.index("--") + 1:] if "--" in argv else []
    a = p.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.render_args = render_args
    if a.iterations < 1 or a.shards < 1:
        sys.exit("error: --iterations and --shards must be at least 1")
    here = os.path.dirname(os.path.abspath(__file__))
    rastergi = a.rastergi or shutil.which("rastergi") or os.path.join(here, "..", "target", "release", "rastergi")
    rastergi = os.path.abspath(rastergi)
    if not os.access(rastergi, os.X_OK):
        sys.exit(f"error: no rastergi binary at {rastergi}; build it (cargo build --release) or give --rastergi")
    try:
        import ray
    except ImportError:
        sys.exit("error: Ray is not installed; `pip install ray` (scripts/setup.sh installs it)")
    os.makedirs(a.work_dir, exist_ok=True)
    work_dir = os.path.abspath(a.work_dir)
    common = [a.scene, "--checkpoint-every", str(a.checkpoint_every)] + a.render_args

    ray.init(address=a.address, include_dashboard=False, log_to_driver=True)
    task = ray.remote(run_task).options(num_gpus=a.gpus_per_task, num_cpus=1, max_retries=a.retries,
                                        retry_exceptions=False)
    start = time.time()
    if a.camera_path:
        cams = camera_frames(a.camera_path)
        jobs = []
        for i, c in enumerate(cams):
            args = common + ["--seed", str(a.seed), "--eye", vec(c["eye"]), "--target", vec(c["target"]),
                             "--up", vec(c["up"])] + (["--fov", f"{c['fov']:.9g}"] if "fov" in c else [])
            out = os.path.abspath(a.out.format(i))
            os.makedirs(os.path.dirname(out), exist_ok=True)
            jobs.append(task.remote(rastergi, args, work_dir, f"frame-{i:04d}", a.iterations, out))
        for name, n, attempt in ray.get(jobs):
            out = a.out.format(int(name.split("-")[1]))
            print(f"{name}: {n} iterations ({attempt} attempt{'s' if attempt > 1 else ''}) → {out}", flush=True)
    else:
        names = [f"shard-{a.seed + k}" for k in range(a.shards)]
        jobs = [task.remote(rastergi, common + ["--seed", str(a.seed + k)], work_dir, names[k], a.iterations,
                            os.path.join(work_dir, names[k] + ".exr"))
                for k in range(a.shards)]
        for name, n, attempt in ray.get(jobs):
            print(f"{name}: {n} iterations ({attempt} attempt{'s' if attempt > 1 else ''})", flush=True)
        merge = [rastergi, "merge"] + [os.path.join(work_dir, n + ".ckpt") for n in names] + ["--out", os.path.abspath(a.out)]
        done = subprocess.run(merge, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(done.stderr.strip().splitlines()[-1])
        print(f"merged {a.shards} shards → {a.out} in {time.time() - start:.1f} s", flush=True)
    ray.shutdown()


if __name__ == "__main__":
    main()
