"""The operator as a user clicks it: Debian's Blender with a window (Xvfb), modal bake,
then one undo takes the bake back."""

import json
import os
import shutil
import subprocess

import pytest
from conftest import BLENDER, ROOT

XVFB = shutil.which("xvfb-run")


@pytest.mark.skipif(BLENDER is None or XVFB is None, reason="needs Debian's blender and xvfb-run (scripts/setup installs both as root)")
def test_click_bake_then_undo(tmp_path):
    out = tmp_path / "seen.json"
    session = os.path.join(ROOT, "tests", "blender_ui_session.py")
    cmd = [XVFB, "-a", "-s", "-screen 0 1280x800x24", BLENDER, "--factory-startup", "--python", session, "--", str(out)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    assert out.is_file(), r.stdout[-3000:] + r.stderr[-3000:]
    seen = json.loads(out.read_text())
    assert "error" not in seen, seen["error"]
    assert seen["invoke"] == ["RUNNING_MODAL"]  # returned at once; the bake runs on its thread
    room = ["Floor", "Ceiling", "Wall Left", "Wall Right", "Wall Back", "Wall Front", "Table", "Chair"]
    assert seen["baked"] == sorted(n + "_baked" for n in room)
    assert "elements" in seen["summary"]
    # The UI kept running while the bake ran on its thread: timers fired throughout.
    assert seen["polls"] >= max(3, seen["seconds"] / 2.0), seen
    assert seen["baked_after_undo"] == 0
    assert seen["meshes_after_undo"] == seen["meshes_before"]
    assert seen["room_after_undo"] == sorted(room)
