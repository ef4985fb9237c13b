"""Zips addon/penumbra (with the compiled module) as an installable add-on:
  <out>/penumbra-<version>-linux-x64.zip   Blender >= 4.2 extension
  <out>/penumbra-<version>-legacy.zip      Blender 3.4 - 4.1 legacy add-on
Usage: python scripts/package.py [OUT_DIR]   (default dist/; scripts/package builds first)
"""

import glob
import os
import re
import sys
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(ROOT, "addon", "penumbra")


def package(out_dir):
    manifest = os.path.join(SRC, "blender_manifest.toml")
    version = re.search(r'^version = "([^"]+)"', open(manifest).read(), re.M).group(1)
    files = sorted(
        glob.glob(os.path.join(SRC, "**", "*.py"), recursive=True) + glob.glob(os.path.join(SRC, "_core*.so"))
    )
    if not any(f.endswith(".so") for f in files):
        raise SystemExit("package: the compiled module is missing from addon/penumbra (run scripts/setup)")
    files.append(manifest)
    os.makedirs(out_dir, exist_ok=True)
    written = []
    # An extension has its manifest at the top of the zip; a legacy add-on zip holds the
    # package folder.
    for name, prefix in (("penumbra-%s-linux-x64.zip" % version, ""), ("penumbra-%s-legacy.zip" % version, "penumbra/")):
        path = os.path.join(out_dir, name)
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            for f in files:
                z.write(f, prefix + os.path.relpath(f, SRC))
        print("package: wrote %s (%d files, %.1f MB)" % (path, len(files), os.path.getsize(path) / 1e6))
        written.append(path)
    return written


if __name__ == "__main__":
    package(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist"))
