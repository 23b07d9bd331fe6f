"""Runs the Cura script `Conduit.py` against a real conduit binary, without Cura.

Usage: CONDUIT_BIN=/path/to/conduit python3 plugins/cura/test_conduit_script.py

Cura loads post-processing scripts as `PostProcessingPlugin.scripts.<Name>` and gives them a
`Script` base class from `PostProcessingPlugin.Script`; this harness builds that package in a
temporary folder with a stub `Script` (settings from a dict) and imports the script from there.
"""

import importlib
import os
import shutil
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))

STUB_SCRIPT = '''
class Script:
    """The part of Cura's Script base class that scripts call."""

    def __init__(self):
        self.values = {}

    def getSettingValueByKey(self, key):
        return self.values.get(key)
'''

CURA_GCODE = [
    ";FLAVOR:Marlin\n;TIME:60\n;Layer height: 0.2\n;Generated with Cura_SteamEngine 5.0.0\n",
    "M82 ;absolute extrusion mode\nG28\nG92 E0\n;LAYER_COUNT:2\n",
    ";LAYER:0\n;TYPE:WALL-OUTER\nG0 F3600 X10 Y10 Z0.2\nG1 F1800 X20 Y10 E0.5\n"
    "G1 X20 Y20 E1\n;MESH:NONMESH\nG0 F600 X20 Y20 Z0.4\n",
    ";LAYER:1\n;TYPE:WALL-OUTER\nG1 F1800 X10 Y20 E1.5\nG1 X10 Y10 E2\n",
    ";End of Gcode\nM104 S0\n",
]


def load_script_class(folder):
    package = os.path.join(folder, "PostProcessingPlugin")
    scripts = os.path.join(package, "scripts")
    os.makedirs(scripts)
    for init in (package, scripts):
        with open(os.path.join(init, "__init__.py"), "w") as f:
            f.write("")
    with open(os.path.join(package, "Script.py"), "w") as f:
        f.write(STUB_SCRIPT)
    shutil.copy(os.path.join(HERE, "Conduit.py"), os.path.join(scripts, "Conduit.py"))
    sys.path.insert(0, folder)
    module = importlib.import_module("PostProcessingPlugin.scripts.Conduit")
    return module


class ConduitScriptTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="conduit-cura-test-")
        cls.module = load_script_class(cls.folder)
        cls.binary = os.environ.get("CONDUIT_BIN", "conduit")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder, ignore_errors=True)

    def script(self, **values):
        script = self.module.Conduit()
        script.values = {"conduit_path": self.binary, "circuit": "", "placement": "", "config": ""}
        script.values.update(values)
        return script

    def test_file_name_equals_class_name_and_settings_are_json(self):
        import json

        settings = json.loads(self.script().getSettingDataString())
        self.assertEqual(settings["key"], "Conduit")
        self.assertEqual(
            sorted(settings["settings"]), ["circuit", "conduit_path", "config", "placement"]
        )

    def test_without_circuit_the_gcode_comes_back_unchanged(self):
        result = self.script().execute(list(CURA_GCODE))
        self.assertEqual(result, CURA_GCODE)

    def test_a_failure_raises_with_conduits_message(self):
        script = self.script(circuit="/nonexistent/board.sch", placement="/nonexistent/p.toml")
        with self.assertRaises(RuntimeError) as caught:
            script.execute(list(CURA_GCODE))
        self.assertIn("board.sch", str(caught.exception))

    def test_edited_text_is_cut_like_the_input(self):
        edited = "".join(CURA_GCODE).replace("G1 X20 Y20 E1\n", "G1 X20 Y20 E1\n; added\n")
        pieces = self.module.split_like(edited, CURA_GCODE)
        self.assertEqual("".join(pieces), edited)
        self.assertEqual(len(pieces), len(CURA_GCODE))
        self.assertTrue(pieces[3].startswith(";LAYER:1\n"))
        self.assertIn("; added\n", pieces[2])


if __name__ == "__main__":
    unittest.main()
