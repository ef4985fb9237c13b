"""A built-in scene, its probes and the two-seed Cycles reference at them, as every part of the
bench that scores bakes at the probes sets them up."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from bench_lib import errors, probes


class Reference:
    """Scene `name` exported into `work/<tag>-<name>`, its probe lattice (spacing
    `cfg.probe_frac` of the diagonal, buried probes left out) and two Cycles bakes there with
    different seeds: `ref` their mean, `noise` the variance of that mean per probe."""

    def __init__(self, name, tag, exe, py, work, cfg):
        self.py, self.cfg = py, cfg
        self.wd = os.path.join(work, f"{tag}-{name}")
        os.makedirs(self.wd, exist_ok=True)
        self.path = os.path.join(self.wd, "scene.json")
        subprocess.run([exe, "scene", name, "-o", self.path], check=True)
        with open(self.path) as f:
            self.scene = json.load(f)
        self.diagonal = probes.scene_diagonal(self.scene)
        self.spacing = self.diagonal * cfg.probe_frac
        _, (pm, pp, px) = probes.scene_probes(self.scene, self.spacing)
        self.keep = ~probes.buried(self.scene, pm, pp, px)
        ab = []
        for seed in (1, 2):
            print(f"bench: {tag} {name}: Cycles reference {seed} ({cfg.ref_samples} spp)",
                  file=sys.stderr, flush=True)
            ab.append(self.cycles(["--samples", cfg.ref_samples, "--seed", seed],
                                  f"ref-{seed}")[1])
        self.ref, self.noise = errors.reference(*ab)
        self.probes = (pm[self.keep], pp[self.keep], px[self.keep])

    def cycles(self, extra, what):
        """A Cycles bake at the probes with `extra` arguments: (its record, kept colours)."""
        from bench_lib.main import cycles

        out = os.path.join(self.wd, f"{what}.npz")
        r = cycles(self.py, ["bake", self.path, out, "--spacing", self.spacing, "--bounces",
                             self.cfg.bounces] + [str(x) for x in extra], what)
        return r, np.load(out)["colors"][self.keep]
