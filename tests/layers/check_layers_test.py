#!/usr/bin/env python3
"""scripts/check-layers on a copy of the tree with an include planted: the check must fail on
each kind of violation it exists for, and pass on the copy as it is and on an allowed include.
Usage: check_layers_test.py REPOSITORY_ROOT"""
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2])
CHECK = ROOT / "scripts" / "check-layers"


def copy_tree(destination):
    """What check-layers reads: the root CMakeLists.txt, docs/design.md and every folder it adds."""
    text = (ROOT / "CMakeLists.txt").read_text()
    shutil.copy(ROOT / "CMakeLists.txt", destination / "CMakeLists.txt")
    (destination / "docs").mkdir()
    shutil.copy(ROOT / "docs" / "design.md", destination / "docs" / "design.md")
    for folder in re.findall(r"^add_subdirectory\((\w+)\)", text, re.M):
        if folder != "tests":
            shutil.copytree(ROOT / folder, destination / folder,
                            ignore=lambda _, names: [n for n in names if n == "corpus"])


class PlantedIncludes(unittest.TestCase):
    def check(self, planted=None, include=None):
        with tempfile.TemporaryDirectory() as scratch:
            root = pathlib.Path(scratch)
            copy_tree(root)
            if planted:
                (root / planted).write_text(f'#include "{include}"\n')
            run = subprocess.run([sys.executable, str(CHECK), str(root)], capture_output=True, text=True)
            return run.returncode, run.stdout + run.stderr

    def test_the_tree_as_it_is_passes(self):
        code, output = self.check()
        self.assertEqual(code, 0, output)

    def test_the_workspace_layout_in_reproject_fails_naming_the_line(self):
        code, output = self.check("reproject/planted.cc", "core/workspace.h")
        self.assertEqual(code, 1, output)
        self.assertIn("reproject/planted.cc:1: includes core/workspace.h", output)

    def test_the_workspace_lock_in_a_viewer_header_fails(self):
        code, output = self.check("viewer/planted.h", "core/workspace_lock.h")
        self.assertEqual(code, 1, output)
        self.assertIn("viewer/planted.h:1", output)

    def test_the_workspace_layout_in_every_data_folder_fails(self):
        for folder in ["mvs", "mesh", "sfm", "colmap", "geometry", "synth"]:
            code, output = self.check(f"{folder}/planted.cc", "core/workspace.h")
            self.assertEqual(code, 1, f"{folder}: {output}")

    def test_the_workspace_layout_in_pipeline_passes(self):
        code, output = self.check("pipeline/planted.cc", "core/workspace.h")
        self.assertEqual(code, 0, output)

    def test_the_part_of_a_folder_it_links_gives_that_parts_headers_alone(self):
        code, output = self.check("eval/planted.cc", "viewer/frame.h")
        self.assertEqual(code, 0, output)
        code, output = self.check("eval/planted.cc", "viewer/renderer.h")
        self.assertEqual(code, 1, output)
        self.assertIn("eval/planted.cc:1: includes viewer/renderer.h", output)

    def test_a_folder_it_does_not_link_fails(self):
        code, output = self.check("viewer/planted.cc", "pipeline/reconstruct.h")
        self.assertEqual(code, 1, output)
        self.assertIn("viewer/planted.cc:1: includes pipeline/", output)


if __name__ == "__main__":
    unittest.main(verbosity=2)
