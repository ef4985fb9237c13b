"""The benchmark suite behind `scripts/bench`. Writes bench/results.json, bench/results.md,
bench/*.png and the README's Performance section, and prints the tables.

Every figure in the outputs comes from this run; nothing is typed in except the paper's
published numbers (PAPER.md), which are labelled as such.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))

from bench_lib import errors, lightmap, penumbra_job, probes, report, solvers, uniform_cycles  # noqa: E402

# Full scenes compared with Cycles (built-in scenes of the CLI). room-78 is the scaling
# room with 78 boxes of clutter (60 + 12·78 = 996 furniture triangles).
SCENES = ["data1", "data2", "chair", "cornell", "room-78"]
PAPER_SCENES = {"data1": "Data 1", "data2": "Data 2", "chair": "Table 3 chair"}


class Config:
    def __init__(self, quick: bool):
        self.quick = quick
        # Probe spacing (fraction of the scene diagonal) for the probe lattice Cycles bakes.
        self.probe_frac = 1 / 10 if quick else 1 / 14
        self.ref_samples = 128 if quick else 512
        self.ref_direct_samples = 64 if quick else 256
        self.ladder = [16, 64] if quick else [16, 64, 256, 1024]
        self.bounces = 64
        # Furniture triangles 60 + 12·N for room-N.
        self.scaling = [10, 30, 78] if quick else [78, 245, 828, 8328]
        # A scaling bake that runs longer is stopped and reported as over the limit; the
        # larger sizes are then not attempted.
        self.scaling_timeout = 40 if quick else 200
        # Both indirect solvers on full bakes (--solvers-only): long enough for the
        # hierarchical solver on room-245.
        self.solver_timeout = 150 if quick else 400
        # room-78 (1k triangles) takes most of the quick budget: full suite only.
        self.scenes = SCENES[:4] if quick else SCENES
        self.render_res = 120 if quick else 200
        self.render_samples = 32 if quick else 128
        # Lightmap rows: texels on a side, Cycles' reference samples (× 2 seeds) and ladder.
        self.lightmap_resolution = 64 if quick else 128
        self.lightmap_ref_samples = 256 if quick else 1024
        self.lightmap_ladder = [16, 64, 256] if quick else [16, 64, 256, 1024]
        # Cycles on a uniform mesh: spacings (diagonal over these) × samples.
        self.uniform_divisions = [25, 50] if quick else [25, 50, 100]
        self.uniform_ladder = [16, 64] if quick else [16, 64, 256]


def machine():
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    ram = 0.0
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemTotal"):
                ram = int(line.split()[1]) / 1024 / 1024
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                         capture_output=True, text=True).stdout.strip()
    return dict(nproc=os.cpu_count(), cpu=cpu, ram_gb=round(ram, 1),
                load_at_start=round(load, 2), python=platform.python_version(),
                commit=rev, date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))


def work_arg(argv):
    """A bench helper's `--work DIR` (target/bench-work unless given), and its other
    arguments."""
    if "--work" in argv:
        i = argv.index("--work")
        return argv[i + 1], argv[:i] + argv[i + 2:]
    return os.path.join(ROOT, "target", "bench-work"), argv


def log(*a):
    print("bench:", *a, file=sys.stderr, flush=True)


def cycles(py, args, what):
    cmd = [py, os.path.join(HERE, "cycles_job.py")] + [str(a) for a in args]
    code, wall, peak, out, err = penumbra_job.timed(cmd)
    if code != 0:
        raise RuntimeError(f"Cycles job {what} failed:\n{err[-2000:]}")
    rec = json.loads(out.strip().splitlines()[-1])
    rec["process_wall"] = wall
    rec["process_peak_mb"] = peak
    return rec


def matched_uniform(exe, scene, work, tag, target, area, extra, timeout):
    """A uniform mesh with about `target` elements: one trial, one correction. (None, None)
    when a bake runs past `timeout` seconds: a uniform mesh makes every occluder a candidate
    at every vertex, which in a cluttered room is far slower than the discontinuity mesh."""
    h = float(np.sqrt(area / (0.433 * target)))
    for it in range(2):
        rec, bake = penumbra_job.run_cli(exe, scene, work, f"{tag}-u{it}",
                                         {**extra, "meshing": "uniform", "element_size": h},
                                         timeout=timeout)
        if bake is None:
            log(f"  uniform mesh stopped after {timeout:.0f} s: row left out")
            return None, None
        n = rec["stats"]["N_e"]
        h *= float(np.sqrt(n / target))
    return rec, bake


def bench_scene(name, exe, py, work, cfg, out):
    log(f"scene {name}")
    sp = os.path.join(work, f"{name}.json")
    subprocess.run([exe, "scene", name, "-o", sp], check=True)
    scene = json.load(open(sp))
    diag = probes.scene_diagonal(scene)
    area = probes.total_area(scene)
    spacing = diag * cfg.probe_frac
    _, (pm, pp, px) = probes.scene_probes(scene, spacing)
    # Cycles bakes every probe; the error leaves out those under a coplanar face.
    keep = ~probes.buried(scene, pm, pp, px)
    pm, pp, px = pm[keep], pp[keep], px[keep]
    res = dict(name=name, diag=diag, area=area, probes=int(len(px)),
               probes_buried=int((~keep).sum()), spacing=spacing,
               triangles=sum(len(p) - 2 for m in scene["meshes"] for p in m["polygons"]))

    # Cycles: references (two seeds, adaptive off) and the sample ladder (defaults).
    cyc = lambda extra, what: cycles(py, ["bake", sp, os.path.join(work, f"{name}-{what}.npz"),
                                          "--spacing", spacing, "--bounces", cfg.bounces]
                                     + extra, what)
    refs = {}
    for kind, n, flag in [("full", cfg.ref_samples, []),
                          ("direct", cfg.ref_direct_samples, ["--direct-only"])]:
        ab = []
        for seed in (1, 2):
            what = f"ref-{kind}-{seed}"
            log(f"  Cycles {what} ({n} samples)")
            r = cyc(["--samples", n, "--seed", seed] + flag, what)
            ab.append(np.load(os.path.join(work, f"{name}-{what}.npz"))["colors"][keep])
            res[f"cycles_{what}"] = r
        ref, noise = errors.reference(*ab)
        refs[kind] = (ref, noise)
        res[f"ref_{kind}_noise_rel_rms"] = errors.noise_rel_rms(ref, noise)
        res[f"ref_{kind}_samples"] = n
    rows = []
    for n in cfg.ladder:
        log(f"  Cycles {n} samples (adaptive)")
        r = cyc(["--samples", n, "--seed", 3, "--adaptive"], f"ladder-{n}")
        x = np.load(os.path.join(work, f"{name}-ladder-{n}.npz"))["colors"][keep]
        rows.append(dict(method=f"Cycles {n} spp", kind="cycles", samples=n,
                         wall=r["seconds"], process_wall=r["process_wall"],
                         peak_mb=r["process_peak_mb"], elements=None,
                         **errors.errors(x, *refs["full"])))
    curve = [(r["wall"], r["rel_rms"]) for r in rows]

    # Penumbra on the full problem (direct + indirect).
    fine = {"element_size": diag / 50, "penumbra_element_size": diag / 250}
    coarse = {"element_size": diag / 12.5, "penumbra_element_size": diag / 62.5}
    full_cfgs = [("Penumbra default", {}), ("Penumbra high", fine),
                 ("Penumbra sampled penumbra", {"penumbra_visibility": "sampled"})]
    prow = []
    for label, st in full_cfgs:
        log(f"  {label}")
        rec, bake = penumbra_job.run_cli(exe, scene, work, f"{name}-{label.split()[-1]}", st)
        x = penumbra_job.colors_at(bake, pm, pp, px)
        prow.append(dict(method=label, kind="penumbra", wall=rec["wall"],
                         peak_mb=rec["peak_mb"], elements=rec["stats"]["N_e"],
                         stats=rec["stats"], settings=rec["settings"],
                         **errors.errors(x, *refs["full"])))
    log("  uniform mesh, same element count")
    limit = max(120.0, 20.0 * prow[0]["wall"])
    rec, bake = matched_uniform(exe, scene, work, f"{name}-full", prow[0]["elements"], area, {},
                                limit)
    if bake is not None:
        x = penumbra_job.colors_at(bake, pm, pp, px)
        prow.append(dict(method="Uniform mesh, same N_e", kind="uniform", wall=rec["wall"],
                         peak_mb=rec["peak_mb"], elements=rec["stats"]["N_e"],
                         stats=rec["stats"], settings=rec["settings"],
                         **errors.errors(x, *refs["full"])))
    for r in prow:
        t, how = errors.cycles_time_at(r["rel_rms"], curve) if r["rel_rms"] > 0 else (
            float("nan"), "error below reference noise")
        r["cycles_time_at_error"] = t
        r["cycles_time_how"] = how
        r["speedup"] = t / r["wall"] if np.isfinite(t) else float("nan")
    res["full_rows"] = prow + rows

    # Direct light only (issue 3): discontinuity vs uniform at equal counts, exact vs sampled.
    drows = []
    nodirect = {"indirect": False}
    for label, st in [("coarse", coarse), ("default", {}), ("high", fine)]:
        for vis in ("exact", "sampled"):
            if vis == "sampled" and label != "default":
                continue
            s = {**nodirect, **st, "penumbra_visibility": vis}
            log(f"  direct only: {label} {vis}")
            rec, bake = penumbra_job.run_cli(exe, scene, work, f"{name}-d-{label}-{vis}", s)
            x = penumbra_job.colors_at(bake, pm, pp, px)
            er = errors.errors(x, *refs["direct"])
            w = er["worst"]
            er["worst"] = dict(mesh=scene["meshes"][int(pm[w])]["name"], polygon=int(pp[w]),
                               position=px[w].tolist(), reference=refs["direct"][0][w].tolist(),
                               ours=x[w].tolist())
            drows.append(dict(method=f"discontinuity {label}, {vis}", kind="discontinuity",
                              level=label, visibility=vis, wall=rec["wall"],
                              peak_mb=rec["peak_mb"], elements=rec["stats"]["N_e"],
                              stats=rec["stats"], **er))
            if vis == "exact":
                rec, bake = matched_uniform(exe, scene, work, f"{name}-d-{label}",
                                            rec["stats"]["N_e"], area, nodirect,
                                            max(120.0, 20.0 * rec["wall"]))
                if bake is None:
                    continue
                x = penumbra_job.colors_at(bake, pm, pp, px)
                drows.append(dict(method=f"uniform, same N_e as {label}", kind="uniform",
                                  level=label, visibility="exact", wall=rec["wall"],
                                  peak_mb=rec["peak_mb"], elements=rec["stats"]["N_e"],
                                  stats=rec["stats"], **errors.errors(x, *refs["direct"])))
    res["direct_rows"] = drows

    if name in PAPER_SCENES:
        log("  uniformly fine mesh for N_e2")
        pes = diag / 125  # the default penumbra_element_size (element_size / 5)
        rec, _ = penumbra_job.run_cli(exe, scene, work, f"{name}-ne2",
                                      {**nodirect, "meshing": "uniform", "element_size": pes},
                                      keep=False)
        res["N_e2"] = rec["stats"]["N_e"]
    out[name] = res
    return res


# Scaling series: the full bake (the targets) and direct light only (the
# discontinuity stages and exact direct light, without the radiosity solve).
SCALING_MODES = {"full": {}, "direct": {"indirect": False}}


def scaling(exe, work, cfg):
    rows = []
    stopped = set()
    for n in cfg.scaling:
        name = f"room-{n}"
        sp = os.path.join(work, f"{name}.json")
        subprocess.run([exe, "scene", name, "-o", sp], check=True)
        scene = json.load(open(sp))
        tris = sum(len(p) - 2 for m in scene["meshes"] for p in m["polygons"])
        furn = sum(len(p) - 2 for m in scene["meshes"] if m["name"] != "Room"
                   for p in m["polygons"])
        for mode, settings in SCALING_MODES.items():
            # A mode stopped at one size is not attempted at the larger ones.
            if mode in stopped:
                continue
            log(f"scaling {name} ({mode})")
            rec, _ = penumbra_job.run_cli(exe, scene, work, f"{name}-{mode}", settings,
                                          keep=False, timeout=cfg.scaling_timeout)
            rows.append(dict(scene=name, mode=mode, triangles=tris, furniture_triangles=furn,
                             wall=rec["wall"], peak_mb=rec["peak_mb"], stats=rec["stats"],
                             timed_out=rec["timed_out"]))
            if rec["timed_out"]:
                log(f"  stopped after {cfg.scaling_timeout} s")
                stopped.add(mode)
        if len(stopped) == len(SCALING_MODES):
            break
    return rows


def profile(exe, work, name):
    """Top functions of the default bake of `name` under `perf` (when installed)."""
    import shutil

    if not shutil.which("perf"):
        return None
    scene = os.path.join(work, f"{name}-default.scene.json")
    data = os.path.join(work, "perf.data")
    log(f"profile {name} with perf")
    r = subprocess.run(["perf", "record", "-F", "499", "-g", "-o", data, exe, "bake", scene,
                        "-o", os.path.join(work, "perf.bake.json")], capture_output=True)
    if r.returncode != 0:
        return None
    rep = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "symbol",
                          "--percent-limit", "2", "--stdio", "-g", "none"],
                         capture_output=True, text=True).stdout
    top = []
    for line in rep.splitlines():
        parts = line.strip().split(None, 2)
        if len(parts) == 3 and parts[0].endswith("%") and parts[1] == "[.]":
            top.append((float(parts[0][:-1]), parts[2].split("  ")[0].strip()))
    return dict(scene=name, top=top[:10])


def render(exe, py, work, cfg):
    name = "cornell"
    sp = os.path.join(work, f"{name}.json")
    bake = os.path.join(work, f"{name}-default.bake.json")
    cam = json.dumps([[0.5, -1.25, 0.5], [0.5, 0.5, 0.5], 30.0])
    out = {}
    for what, extra, samples in [("cycles", [], cfg.render_samples),
                                 ("penumbra", ["--bake", bake], 16)]:
        png = os.path.join(work, f"render-{what}.png")
        log(f"render {what}")
        r = cycles(py, ["render", sp, png, "--samples", samples, "--camera", cam,
                        "--resolution", cfg.render_res, "--bounces", cfg.bounces] + extra,
                   f"render-{what}")
        out[what] = dict(png=png, seconds=r["seconds"], samples=samples)
    return out


def rescore_worst(res, work):
    """Fills the worst-probe record of each scene's default direct-light bake from the files
    a run left in `work` (for results written before that record existed)."""
    for name, sc in res["scenes"].items():
        row = next(r for r in sc["direct_rows"] if r["method"] == "discontinuity default, exact")
        if isinstance(row.get("worst"), dict):
            continue
        scene = json.load(open(os.path.join(work, f"{name}.json")))
        _, (pm, pp, px) = probes.scene_probes(scene, sc["spacing"])
        keep = ~probes.buried(scene, pm, pp, px)
        pm, pp, px = pm[keep], pp[keep], px[keep]
        ab = [np.load(os.path.join(work, f"{name}-ref-direct-{s}.npz"))["colors"][keep]
              for s in (1, 2)]
        ref, noise = errors.reference(*ab)
        with open(os.path.join(work, f"{name}-d-default-exact.bake.json")) as f:
            x = penumbra_job.colors_at(json.load(f), pm, pp, px)
        w = errors.errors(x, ref, noise)["worst"]
        row["worst"] = dict(mesh=scene["meshes"][int(pm[w])]["name"], polygon=int(pp[w]),
                            position=px[w].tolist(), reference=ref[w].tolist(),
                            ours=x[w].tolist())


def main():
    ap = argparse.ArgumentParser(prog="scripts/bench")
    ap.add_argument("--quick", action="store_true", help="small suite (a few minutes)")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench"))
    ap.add_argument("--work", default=os.path.join(ROOT, "target", "bench-work"))
    ap.add_argument("--scenes", nargs="*", help=f"default: {' '.join(SCENES)} "
                    "(--quick: the first four)")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite the markdown and plots from OUT/results.json")
    ap.add_argument("--exe", default=os.path.join(ROOT, "target", "release", "penumbra"))
    ap.add_argument("--no-scaling", action="store_true",
                    help="skip the scaling series (room-N bakes of growing size)")
    ap.add_argument("--lightmap-only", action="store_true",
                    help="only the lightmap rows (Penumbra against Cycles' bake to an image); "
                    "writes OUT/lightmaps.json and their section of OUT/results.md and README.md")
    ap.add_argument("--uniform-only", action="store_true",
                    help="only Cycles on a uniform mesh (a vertex-colour user's bake) against "
                    "Penumbra and Cycles at the probes; writes OUT/cycles_uniform.json and its "
                    "section of OUT/results.md and README.md")
    ap.add_argument("--tolerance", action="store_true",
                    help="only direct light refined to tolerances 3 %%…0.1 %% against uniform "
                    "meshes, and room-8328 direct-only (bench_lib/tolerance.py)")
    ap.add_argument("--solvers-only", action="store_true",
                    help="only the two indirect solvers on full bakes (default scenes plus "
                    "room-245; --quick: the first four); writes OUT/solvers.json and its section "
                    "of OUT/results.md and README.md")
    a = ap.parse_args()
    if a.report_only and a.lightmap_only:
        with open(os.path.join(a.out, "lightmaps.json")) as f:
            lm = json.load(f)
        write_lightmaps(lm["scenes"], lm["machine"], lm["command"], a.out)
        return
    if a.report_only:
        with open(os.path.join(a.out, "results.json")) as f:
            res = json.load(f)
        if os.path.isdir(a.work):
            rescore_worst(res, a.work)
            with open(os.path.join(a.out, "results.json"), "w") as f:
                json.dump(res, f, indent=1, default=float)
        print(report.write(res, a.out))
        return
    cfg = Config(a.quick)
    a.scenes = a.scenes or cfg.scenes
    os.makedirs(a.work, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    if a.tolerance:
        from bench_lib import tolerance

        md = tolerance.run(a, cfg, machine(), lambda args, what: cycles(sys.executable, args, what),
                           log, matched_uniform, ROOT)
        if os.path.abspath(a.out) == os.path.join(ROOT, "bench"):
            tolerance.splice(os.path.join(ROOT, "README.md"),
                             md.replace("(error_vs_elements.png)", "(bench/error_vs_elements.png)"))
        print(md)
        return
    t0 = time.perf_counter()
    command = "scripts/bench" + (" --quick" if a.quick else "")
    if a.lightmap_only:
        command += " --lightmap-only" + (f" --scenes {' '.join(a.scenes)}" if a.scenes != cfg.scenes
                                         else "")
        rows = [lightmap.bench_scene(n, a.exe, sys.executable, a.work, cfg) for n in a.scenes]
        rows = [r for r in rows if r is not None]
        write_lightmaps(rows, machine(), command, a.out)
        return
    if a.uniform_only:
        command += " --uniform-only" + (f" --scenes {' '.join(a.scenes)}" if a.scenes != cfg.scenes
                                        else "")
        rows = [uniform_cycles.bench_scene(n, a.exe, sys.executable, a.work, cfg)
                for n in a.scenes]
        write_uniform(rows, machine(), command, a.out)
        return
    if a.solvers_only:
        names = a.scenes if a.scenes != cfg.scenes else cfg.scenes + ([] if a.quick else ["room-245"])
        command += " --solvers-only" + (f" --scenes {' '.join(names)}" if a.scenes != cfg.scenes
                                        else "")
        rows = [solvers.bench_scene(n, a.exe, sys.executable, a.work, cfg, cfg.solver_timeout)
                for n in names]
        mach = machine()
        write_section("solvers", rows, solvers.section(rows, mach, command), mach, command,
                      a.out, solvers.START, solvers.END)
        return
    res = dict(machine=machine(), quick=a.quick, config=vars(cfg), command=command, scenes={})
    res["lightmaps"] = []
    for name in a.scenes:
        bench_scene(name, a.exe, sys.executable, a.work, cfg, res["scenes"])
        row = lightmap.bench_scene(name, a.exe, sys.executable, a.work, cfg)
        if row is not None:
            res["lightmaps"].append(row)
    res["cycles_uniform"] = [uniform_cycles.bench_scene(n, a.exe, sys.executable, a.work, cfg)
                             for n in a.scenes]
    res["scaling"] = [] if a.no_scaling else scaling(a.exe, a.work, cfg)
    res["profile"] = profile(a.exe, a.work, a.scenes[-1])
    if "cornell" in a.scenes:
        res["render"] = render(a.exe, sys.executable, a.work, cfg)
    res["suite_seconds"] = time.perf_counter() - t0
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(res, f, indent=1, default=float)
    text = report.write(res, a.out)
    print(text)
    write_lightmaps(res["lightmaps"], res["machine"], command, a.out)
    write_uniform(res["cycles_uniform"], res["machine"], command, a.out)


def write_lightmaps(rows, mach, command, out):
    """The lightmap rows: OUT/lightmaps.json and their section. Nothing when no scene has a
    lightmap row."""
    if rows:
        write_section("lightmaps", rows, lightmap.section(rows, mach, command), mach, command,
                      out, lightmap.START, lightmap.END)


def write_uniform(rows, mach, command, out):
    """Cycles on a uniform mesh: OUT/cycles_uniform.json and its section."""
    write_section("cycles_uniform", rows, uniform_cycles.section(rows, mach, command), mach,
                  command, out, uniform_cycles.START, uniform_cycles.END)


def write_section(name, rows, text, mach, command, out, start, end):
    """OUT/NAME.json, and `text` between `start` and `end` in OUT/results.md and (for the
    repository's own bench/) README.md."""
    with open(os.path.join(out, f"{name}.json"), "w") as f:
        json.dump(dict(machine=mach, command=command, scenes=rows), f, indent=1, default=float)
    md = os.path.join(out, "results.md")
    if not os.path.exists(md):
        open(md, "w").close()
    lightmap.splice(md, text, start, end)
    if os.path.abspath(out) == os.path.join(ROOT, "bench"):
        lightmap.splice(os.path.join(ROOT, "README.md"), text, start, end)
    print(text)


if __name__ == "__main__":
    main()
