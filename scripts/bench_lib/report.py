"""Tables (markdown), plots (matplotlib) and the target checks, all from results.json."""
from __future__ import annotations

import math
import os
import re

import numpy as np

# Published figures of the paper (PAPER.md, Tables 2–4), IBM RS/6000 model 340.
PAPER = {
    "data1": dict(N_f1=8, N_f2=20, N_d=40, N_p=486, N_e1=3485, N_e2=6090, T_d=0.12,
                  T_m=1.77, T_rs=156.63, T_sdw=0.03, T_isr=0.04, T_idd=0.02, T_lop=0.01,
                  T_lit=0.01, T_div=0.01),
    "data2": dict(N_f1=721, N_f2=2495, N_d=3116, N_p=6030, N_e1=11230, N_e2=17150,
                  T_d=166.58, T_m=15.28, T_rs=289.02, T_sdw=0.21, T_isr=154.48, T_idd=3.76,
                  T_lop=2.13, T_lit=5.50, T_div=0.50),
    # Table 3 (discontinuity column); N_f is the face count (no N_f2, N_d, N_e2 given).
    "chair": dict(N_f1=79, N_p=3166, N_e1=3166, T_d=0.83, T_m=3.56, T_rs=7.85),
}
TD_PARTS = ["T_sdw", "T_isr", "T_idd", "T_lop", "T_lit", "T_div"]
STAGES = TD_PARTS + ["T_m", "T_direct", "T_rs"]


def fmt(v, nd=3):
    if v is None:
        return "–"
    if isinstance(v, (int, np.integer)):
        return f"{v:,}"
    if isinstance(v, float) and not math.isfinite(v):
        return "–"
    if v == 0:
        return "0"
    if abs(v) >= 1000:
        return f"{v:,.0f}"
    return f"{v:.{nd}g}" if abs(v) < 1 else f"{v:.{nd + 1}g}"


def pct(v):
    return "–" if v is None or not math.isfinite(v) else f"{100 * v:.2f} %"


def table(head, rows):
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def t_d(st):
    return sum(st[k] for k in TD_PARTS)


def fit_exponent(x, y):
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    if len(x) < 2:
        return float("nan")
    return float(np.polyfit(x, y, 1)[0])


def plots(res, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    scenes = list(res["scenes"].values())
    files = {}
    if scenes:
        n = len(scenes)
        fig, axs = plt.subplots(1, n, figsize=(3.6 * n, 3.4), squeeze=False)
        for ax, sc in zip(axs[0], scenes):
            cy = [r for r in sc["full_rows"] if r["kind"] == "cycles"]
            ax.loglog([r["wall"] for r in cy], [max(r["rel_rms"], 1e-5) for r in cy], "k.-",
                      label="Cycles (16…1024 spp)")
            for r in cy:
                ax.annotate(str(r["samples"]), (r["wall"], max(r["rel_rms"], 1e-5)),
                            fontsize=7)
            for r, m in zip([r for r in sc["full_rows"] if r["kind"] != "cycles"], "osD^"):
                ax.loglog([r["wall"]], [max(r["rel_rms"], 1e-5)], m, label=r["method"])
            ax.set_title(sc["name"])
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel("wall time (s)")
            ax.grid(True, which="both", alpha=0.3)
        axs[0][0].set_ylabel("relative RMS error")
        axs[0][0].legend(fontsize=6)
        fig.tight_layout()
        files["error_vs_time"] = "error_vs_time.png"
        fig.savefig(os.path.join(out, files["error_vs_time"]), dpi=110)
        plt.close(fig)

        fig, axs = plt.subplots(1, n, figsize=(3.6 * n, 3.4), squeeze=False)
        for ax, sc in zip(axs[0], scenes):
            for kind, m in [("discontinuity", "o-"), ("uniform", "s--")]:
                rr = [r for r in sc["direct_rows"] if r["kind"] == kind
                      and r["visibility"] == "exact"]
                rr.sort(key=lambda r: r["elements"])
                ax.loglog([r["elements"] for r in rr], [max(r["rel_rms"], 1e-5) for r in rr],
                          m, label=f"{kind} mesh")
            ax.set_title(f"{sc['name']} (direct light)")
            ax.set_xlabel("elements")
            ax.grid(True, which="both", alpha=0.3)
        axs[0][0].set_ylabel("relative RMS error")
        axs[0][0].legend(fontsize=7)
        fig.tight_layout()
        # `scripts/bench --tolerance` draws this figure from its own curves when it has run.
        if not os.path.exists(os.path.join(out, "tolerance.json")):
            files["error_vs_elements"] = "error_vs_elements.png"
            fig.savefig(os.path.join(out, files["error_vs_elements"]), dpi=110)
        plt.close(fig)

    if any(not r.get("timed_out") for r in res["scaling"]):
        fig, ax = plt.subplots(figsize=(5.6, 4.0))
        for mode, style in [("full", ("o-", "s--", "C0")), ("direct", ("o:", "s-.", "C1"))]:
            rows = scaling_rows(res, mode)
            sc = [r for r in rows if not r.get("timed_out")]
            if not sc:
                continue
            x = [r["triangles"] for r in sc]
            t = [r["wall"] for r in sc]
            m = [r["peak_mb"] / 1024 for r in sc]
            ax.loglog(x, t, style[0], color=style[2],
                      label=f"{mode}: wall time (s), exponent {fit_exponent(x, t):.2f}")
            ax.loglog(x, m, style[1], color=style[2], alpha=0.6,
                      label=f"{mode}: peak memory (GB), exponent {fit_exponent(x, m):.2f}")
            for r in rows:
                if r.get("timed_out"):
                    ax.loglog([r["triangles"]], [r["wall"]], "^", color=style[2],
                              label=f"{mode}: stopped at {r['wall']:.0f} s (lower bound)")
        ax.set_xlabel("triangles in the scene (room-N)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        files["scaling"] = "scaling.png"
        fig.savefig(os.path.join(out, files["scaling"]), dpi=110)
        plt.close(fig)

    rd = res.get("render")
    if rd and all(os.path.exists(rd[k]["png"]) for k in ("cycles", "penumbra")):
        fig, axs = plt.subplots(1, 2, figsize=(7, 3.7))
        for ax, k, title in [(axs[0], "cycles", f"Cycles render, {rd['cycles']['samples']} spp"
                              f" ({rd['cycles']['seconds']:.1f} s)"),
                             (axs[1], "penumbra", "Penumbra bake (emission from colours)")]:
            ax.imshow(plt.imread(rd[k]["png"]))
            ax.set_title(title, fontsize=9)
            ax.axis("off")
        fig.tight_layout()
        files["render"] = "render_cornell.png"
        fig.savefig(os.path.join(out, files["render"]), dpi=110)
        plt.close(fig)
    elif rd and os.path.exists(os.path.join(out, "render_cornell.png")):
        # --report-only after the work directory is gone: the composite of that run stays.
        files["render"] = "render_cornell.png"
    return files


def targets(res):
    """(target, measured, met: True/False/None) rows."""
    rows = []
    for name, sc in res["scenes"].items():
        d = next(r for r in sc["full_rows"] if r["method"] == "Penumbra default")
        how = d["cycles_time_how"]
        rows.append((f"{name}: at equal error, Penumbra default ≥ 10× faster than Cycles",
                     f"{fmt(d['speedup'])}× ({how}; Penumbra {fmt(d['wall'])} s at "
                     f"{pct(d['rel_rms'])}, Cycles would need {fmt(d['cycles_time_at_error'])} s)",
                     bool(d["speedup"] >= 10) if math.isfinite(d["speedup"]) else None))
    for name, sc in res["scenes"].items():
        for lvl in ("coarse", "default", "high"):
            dm = [r for r in sc["direct_rows"] if r["kind"] == "discontinuity"
                  and r["level"] == lvl and r["visibility"] == "exact"]
            un = [r for r in sc["direct_rows"] if r["kind"] == "uniform" and r["level"] == lvl]
            if not dm or not un:
                continue
            q = dm[0]["rel_rms"] / un[0]["rel_rms"] if un[0]["rel_rms"] > 0 else float("nan")
            rows.append((f"{name} {lvl}: discontinuity error ≤ 0.5 × uniform at equal N_e "
                         f"(direct light)",
                         f"{fmt(q)} ({pct(dm[0]['rel_rms'])} with {dm[0]['elements']:,} vs "
                         f"{pct(un[0]['rel_rms'])} with {un[0]['elements']:,})",
                         bool(q <= 0.5) if math.isfinite(q) else None))
    if "data2" in res["scenes"]:
        d = next(r for r in res["scenes"]["data2"]["full_rows"]
                 if r["method"] == "Penumbra default")
        rows.append(("Data 2 whole bake ≤ 2 s", f"{fmt(d['wall'])} s", d["wall"] <= 2.0))
    sc = scaling_rows(res, "full")
    big = [r for r in sc if r["furniture_triangles"] >= 90_000]
    if big:
        r = big[-1]
        if r.get("timed_out"):
            rows.append((f"{r['furniture_triangles']:,} furniture triangles ≤ 60 s",
                         f"not finished: stopped after {fmt(r['wall'])} s", False))
            rows.append((f"{r['furniture_triangles']:,} furniture triangles ≤ 4 GB peak",
                         f"{fmt(r['peak_mb'] / 1024)} GB when stopped",
                         False if r["peak_mb"] > 4096 else None))
        else:
            rows.append((f"{r['furniture_triangles']:,} furniture triangles ≤ 60 s",
                         f"{fmt(r['wall'])} s", r["wall"] <= 60))
            rows.append((f"{r['furniture_triangles']:,} furniture triangles ≤ 4 GB peak",
                         f"{fmt(r['peak_mb'] / 1024)} GB", r["peak_mb"] <= 4096))
    elif res.get("quick"):
        rows.append(("100k triangles ≤ 60 s and ≤ 4 GB", "not run (quick mode)", None))
    else:
        stop = [r for r in sc if r.get("timed_out")]
        why = (f"not attempted: {stop[0]['scene']} ({stop[0]['furniture_triangles']:,} furniture "
               f"triangles) was already stopped at {fmt(stop[0]['wall'])} s") if stop \
            else "not run"
        rows.append(("100k triangles ≤ 60 s and ≤ 4 GB", why, False if stop else None))
    done = [r for r in sc if not r.get("timed_out")]
    if len(done) >= 2:
        e = fit_exponent([r["triangles"] for r in done], [r["wall"] for r in done])
        rows.append(("time exponent vs triangles ≤ 1.3",
                     f"{e:.2f} (over {len(done)} finished sizes)", e <= 1.3))
    return rows


def scaling_rows(res, mode):
    """The scaling rows of one mode ("full" or "direct"); rows of results written before
    the direct series existed are full bakes."""
    return [r for r in res["scaling"] if r.get("mode", "full") == mode]


def findings(res):
    """Plain statements derived from the numbers: dominant stages, where we lose."""
    out = []
    for name, sc in res["scenes"].items():
        d = next(r for r in sc["full_rows"] if r["method"] == "Penumbra default")
        st = d["stats"]
        parts = {k: st[k] for k in STAGES}
        other = d["wall"] - sum(parts.values())
        parts["outside stages (parse, output, process)"] = other
        k, v = max(parts.items(), key=lambda kv: kv[1])
        out.append(f"{name}: the largest share of Penumbra's {fmt(d['wall'])} s wall time "
                   f"is {k} = {fmt(v)} s ({100 * v / d['wall']:.0f} %).")
        if math.isfinite(d["speedup"]) and d["speedup"] < 10:
            out.append(f"{name}: **below the 10× target** — Cycles reaches Penumbra's error "
                       f"({pct(d['rel_rms'])}) in {fmt(d['cycles_time_at_error'])} s "
                       f"({d['cycles_time_how']}), Penumbra takes {fmt(d['wall'])} s.")
        dd = [r for r in sc["direct_rows"] if r["method"] == "discontinuity default, exact"]
        if dd and isinstance(dd[0].get("worst"), dict):
            w = dd[0]["worst"]
            out.append(f"{name}: largest direct-light error of the default bake "
                       f"({pct(dd[0]['rel_max'])} of the mean) at {w['mesh']} polygon "
                       f"{w['polygon']}, ({', '.join(f'{c:.3f}' for c in w['position'])}): "
                       f"Cycles {w['reference'][0]:.3g}, Penumbra {w['ours'][0]:.3g} (red).")
        if st.get("N_p", 0) == 0 and st.get("T_rs", 0) == 0:
            out.append(f"{name}: no indirect light in this build (N_p = 0, T_rs = 0): the "
                       f"full-problem error is the missing indirect light, not meshing.")
    for mode in ("full", "direct"):
        for r in [r for r in scaling_rows(res, mode) if not r.get("timed_out")][-1:]:
            st = r["stats"]
            parts = {k: st[k] for k in STAGES}
            k, v = max(parts.items(), key=lambda kv: kv[1])
            out.append(f"{r['scene']} ({r['triangles']:,} triangles, {mode} bake): largest "
                       f"stage {k} = {fmt(v)} s of {fmt(r['wall'])} s.")
    return out


def write(res, out):
    files = plots(res, out)
    m = res["machine"]
    L = []
    L.append("## Performance\n")
    L.append(f"Generated by `{res['command']}` (commit {m['commit']}, {m['date']}, suite "
             f"{res['suite_seconds'] / 60:.1f} min). Machine: {m['nproc']} cores, {m['cpu']}, "
             f"{m['ram_gb']} GB RAM, load average {m['load_at_start']} at start (shared "
             f"machine). Penumbra and Cycles both use all cores.\n")
    cfg = res["config"]
    L.append("**Method.** Times are whole processes: the `penumbra bake` CLI as a subprocess "
             "(wall time, peak RSS of that child, JSON in and out included); Cycles: the "
             "`bpy.ops.object.bake` call in its own bpy process and that process's peak RSS. "
             "Errors are measured at probe points: every receiver polygon is split into a "
             f"lattice of spacing diagonal × {cfg['probe_frac']:.3g}; its interior vertices are "
             "the probes; Cycles bakes vertex colours (Diffuse: direct + indirect + colour) on "
             "that lattice, Penumbra's bake is interpolated there barycentrically. Reference: "
             f"two Cycles bakes with different seeds at {cfg['ref_samples']} samples "
             f"(direct-only reference: {cfg['ref_direct_samples']}), adaptive sampling off, "
             f"{cfg['bounces']} diffuse bounces; their mean is the reference and the variance "
             "of that mean, (a − b)²/4 per probe, is subtracted from every squared error. "
             "Relative RMS = RMSE / mean of reference; max = largest per-probe error / mean "
             "of reference. Cycles rows use its default adaptive sampling (bounces as the "
             "reference), seed 3. Cycles bakes only the probe lattice (a few thousand vertex "
             "corners), Penumbra its whole output mesh, so the comparison favours Cycles. "
             "\"Cycles time at this error\" interpolates Cycles' "
             "error-vs-time curve in log-log (extrapolated beyond its ends, marked).\n")

    L.append("### Speed against error (full problem: direct + indirect + colour)\n")
    for name, sc in res["scenes"].items():
        L.append(f"**{name}** — {sc['triangles']:,} input triangles, {sc['probes']:,} probes "
                 f"({sc['probes_buried']} more under coplanar faces or inside solids left out); "
                 f"reference noise {pct(sc['ref_full_noise_rel_rms'])} RMS (subtracted).\n")
        rows = []
        for r in sc["full_rows"]:
            rows.append([r["method"], fmt(r["wall"]), fmt(r["peak_mb"]),
                         fmt(r["elements"]), pct(r["rel_rms"]), pct(r["rel_max"]),
                         "" if r["kind"] == "cycles" else
                         f"{fmt(r['cycles_time_at_error'])} ({r['cycles_time_how']})",
                         "" if r["kind"] == "cycles" else fmt(r["speedup"])])
        L.append(table(["method", "wall (s)", "peak (MB)", "elements", "rel. RMS", "max",
                        "Cycles time at this error (s)", "÷ Penumbra time"], rows) + "\n")
    if "error_vs_time" in files:
        L.append(f"![error vs time]({files['error_vs_time']})\n")

    L.append("### Direct light: discontinuity vs uniform mesh, exact vs sampled penumbra\n")
    L.append("`indirect: false` bakes against the Cycles direct-only reference (Diffuse bake, "
             "direct + colour). Uniform rows: `meshing: uniform` with element_size tuned so "
             "the element count matches the discontinuity row. Time of the direct and "
             "indirect stages (T_direct, T_rs) is from the full default bake.\n")
    for name, sc in res["scenes"].items():
        d = next(r for r in sc["full_rows"] if r["method"] == "Penumbra default")["stats"]
        L.append(f"**{name}** — T_direct {fmt(d['T_direct'])} s, T_rs (indirect) "
                 f"{fmt(d['T_rs'])} s, N_p {d['N_p']:,}; reference noise "
                 f"{pct(sc['ref_direct_noise_rel_rms'])}.\n")
        rows = [[r["method"], fmt(r["wall"]), fmt(r["stats"]["T_direct"]), fmt(r["elements"]),
                 fmt(r["stats"]["pairs_penumbra"]), pct(r["rel_rms"]), pct(r["rel_max"])]
                for r in sc["direct_rows"]]
        L.append(table(["mesh / penumbra visibility", "wall (s)", "T_direct (s)", "elements",
                        "penumbra vertex×light pairs", "rel. RMS", "max"], rows) + "\n")
    if "error_vs_elements" in files:
        L.append(f"![error vs elements]({files['error_vs_elements']})\n")

    L.append("### The paper's tables beside ours\n")
    L.append("Ours: default full bake on this machine. Paper: IBM RS/6000 model 340 (1995). "
             "N_e1 = our element count (fine in penumbra only); N_e2 = elements of a uniform "
             "mesh at the penumbra element size; T_d = T_sdw + T_isr + T_idd + T_lop + T_lit "
             "+ T_div; T_rs (ours) = T_direct + T_rs (all lighting).\n")
    keys = ["N_f1", "N_f2", "N_d", "N_p", "N_e1", "N_e2", "T_d", "T_m", "T_rs"] + TD_PARTS
    head = ["figure"]
    cols = []
    for name, label in [("data1", "Data 1"), ("data2", "Data 2"), ("chair", "Table 3 chair")]:
        if name not in res["scenes"]:
            continue
        sc = res["scenes"][name]
        st = next(r for r in sc["full_rows"] if r["method"] == "Penumbra default")["stats"]
        ours = dict(st, N_e1=st["N_e"], N_e2=sc.get("N_e2"), T_d=t_d(st),
                    T_rs=st["T_direct"] + st["T_rs"])
        head += [f"{label} ours", f"{label} paper"]
        cols.append((ours, PAPER[name]))
    rows = [[k] + sum([[fmt(o.get(k)), fmt(p.get(k))] for o, p in cols], []) for k in keys]
    L.append(table(head, rows) + "\n")

    L.append("### Scaling: the room with 1k … 100k triangles of furniture\n")
    sc = res["scaling"]
    rows = []
    for r in sc:
        mode = r.get("mode", "full")
        if r.get("timed_out"):
            rows.append([r["scene"], mode, fmt(r["furniture_triangles"]), fmt(r["triangles"]),
                         f"> {fmt(r['wall'])} (stopped)", f"≥ {fmt(r['peak_mb'])}"]
                        + ["–"] * 8)
            continue
        st = r["stats"]
        rows.append([r["scene"], mode, fmt(r["furniture_triangles"]), fmt(r["triangles"]),
                     fmt(r["wall"]), fmt(r["peak_mb"]), fmt(st["N_e"]), fmt(st.get("N_f2")),
                     fmt(st["T_sdw"] + st["T_isr"]), fmt(t_d(st) - st["T_sdw"] - st["T_isr"]),
                     fmt(st["T_m"]), fmt(st["T_direct"]), fmt(st["T_rs"])])
    L.append("Each size is baked twice: the full bake (direct + indirect, the issue's "
             "targets) and direct light only (`\"indirect\": false`). T_sdw+isr: shadow "
             "volumes and their polygons on the receivers; T_arr: edge cutting, "
             "arrangement, relations and merging (T_idd + T_lop + T_lit + T_div).\n")
    L.append(table(["scene", "mode", "furniture tris", "all tris", "wall (s)", "peak (MB)",
                    "elements", "N_f2", "T_sdw+isr", "T_arr", "T_m", "T_direct", "T_rs"],
                   rows) + "\n")
    for mode in ("full", "direct"):
        done = [r for r in scaling_rows(res, mode) if not r.get("timed_out")]
        if len(done) >= 2:
            x = [r["triangles"] for r in done]
            L.append(f"Fitted exponents, {mode} bake (log-log over {len(done)} finished "
                     f"sizes): time {fit_exponent(x, [r['wall'] for r in done]):.2f}, peak "
                     f"memory {fit_exponent(x, [r['peak_mb'] for r in done]):.2f}.\n")
    if "scaling" in files:
        L.append(f"![scaling]({files['scaling']})\n")
    if "render" in files:
        L.append("### Render\n")
        L.append("Cornell box: Cycles render of the original scene (left) and Penumbra's "
                 "default bake rendered as emission from its colour attribute (right), "
                 "Standard view transform.\n")
        L.append(f"![render]({files['render']})\n")

    L.append("### Targets\n")
    L.append(table(["target", "measured", "met"],
                   [[t, m, {True: "yes", False: "**NO**", None: "–"}[ok]]
                    for t, m, ok in targets(res)]) + "\n")
    L.append("### Findings (derived from the stats of this run)\n")
    L += [f"- {f}" for f in findings(res)]
    pr = res.get("profile")
    if pr and pr["top"]:
        L.append(f"\n`perf record` of the default bake of {pr['scene']} — functions over 2 % "
                 "of samples (self time):\n")
        L.append(table(["% samples", "function"],
                       [[f"{p:.1f}", f"`{s}`"] for p, s in pr["top"]]) + "\n")
    text = "\n".join(L) + "\n"
    with open(os.path.join(out, "results.md"), "w") as f:
        f.write(text)
    splice_readme(text, out)
    return text


README_START = "<!-- performance: generated by scripts/bench, do not edit by hand -->"
README_END = "<!-- end of performance -->"


def splice_readme(text, out):
    """Puts the report into README.md between the markers (appended the first time), its
    image links made relative to the repository root. Only a run that writes to the
    repository's own bench/ directory does this, so trial runs elsewhere leave it alone."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if os.path.abspath(out) != os.path.join(root, "bench"):
        return
    rel = os.path.relpath(out, root)
    body = re.sub(r"!\[([^\]]*)\]\(([^)/]+)\)", lambda m: f"![{m[1]}]({rel}/{m[2]})", text)
    path = os.path.join(root, "README.md")
    with open(path) as f:
        readme = f.read()
    block = f"{README_START}\n{body}{README_END}"
    if README_START in readme and README_END in readme:
        head, rest = readme.split(README_START, 1)
        tail = rest.split(README_END, 1)[1]
        readme = head + block + tail
    else:
        readme = readme.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(readme)
