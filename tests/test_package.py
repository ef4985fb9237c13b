"""The add-on zips install and register: as an extension in Blender 5 (bpy module) and as
a legacy add-on in Debian's Blender 3.4. Both run against throw-away user folders."""

import os
import subprocess
import sys

import pytest
from conftest import BLENDER, ROOT

sys.path.insert(0, os.path.join(ROOT, "scripts"))
from package import package  # noqa: E402

CHECK = "import bpy; print('REGISTERED', hasattr(bpy.types.Scene, 'penumbra') and hasattr(bpy.ops.penumbra, 'bake'))"


@pytest.fixture(scope="module")
def zips(tmp_path_factory):
    extension, legacy = package(str(tmp_path_factory.mktemp("dist")))
    return extension, legacy


def run(cmd, env):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=dict(os.environ, **env), stdin=subprocess.DEVNULL)


def test_extension_installs_in_blender_5(zips, tmp_path):
    code = (
        "import bpy\n"
        "r = bpy.ops.extensions.package_install_files(filepath=%r, repo='user_default', enable_on_install=True)\n"
        "assert r == {'FINISHED'}, r\n" % zips[0]
    ) + CHECK
    r = run([sys.executable, "-c", code], {"BLENDER_USER_RESOURCES": str(tmp_path)})
    assert "REGISTERED True" in r.stdout, r.stdout + r.stderr


@pytest.mark.skipif(BLENDER is None, reason="Debian's blender is not installed")
def test_legacy_addon_installs_in_blender_3_4(zips, tmp_path):
    code = (
        "import bpy\n"
        "bpy.ops.preferences.addon_install(filepath=%r)\n"
        "bpy.ops.preferences.addon_enable(module='penumbra')\n" % zips[1]
    ) + CHECK
    r = run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", code], {"BLENDER_USER_SCRIPTS": str(tmp_path)})
    assert "REGISTERED True" in r.stdout, r.stdout + r.stderr


def _blender_ext():
    """Blender's own extension tool, shipped inside the bpy wheel."""
    import bpy

    root = bpy.utils.system_resource("SCRIPTS")
    for dirpath, _, files in os.walk(root):
        if "blender_ext.py" in files and dirpath.endswith(os.path.join("bl_pkg", "cli")):
            return os.path.join(dirpath, "blender_ext.py")
    pytest.skip("blender_ext.py is not in this bpy wheel")


def test_manifest_passes_blenders_validator():
    # Regression: a tagline over 64 characters made Blender refuse the extension.
    r = subprocess.run(
        [sys.executable, _blender_ext(), "validate", os.path.join(ROOT, "addon", "penumbra")],
        capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL,
    )
    assert r.returncode == 0, r.stdout + r.stderr
