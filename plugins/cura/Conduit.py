# Cura post-processing script: runs `conduit postprocess` on the sliced G-code.
#
# Copy this file into Cura's scripts folder (Help > Show Configuration Folder, then `scripts/`),
# restart Cura and add "Conduit (printed electronics)" in Extensions > Post Processing > Modify
# G-Code. The script holds no algorithm: it writes Cura's G-code to a temporary file, runs the
# conduit binary on it and hands the result back to Cura. See README.md beside it.

import os
import subprocess
import tempfile

from ..Script import Script


class Conduit(Script):
    """Passes Cura's G-code through `conduit postprocess` (file name = class name, as Cura needs)."""

    def getSettingDataString(self):
        return """{
            "name": "Conduit (printed electronics)",
            "key": "Conduit",
            "metadata": {},
            "version": 2,
            "settings": {
                "conduit_path": {
                    "label": "conduit binary",
                    "description": "Full path of the conduit program (or just conduit when it is on the PATH).",
                    "type": "str",
                    "default_value": "conduit"
                },
                "circuit": {
                    "label": "Circuit (.sch or .brd)",
                    "description": "EAGLE schematic or board to build into the print. Leave empty to only check the G-code.",
                    "type": "str",
                    "default_value": ""
                },
                "placement": {
                    "label": "Placement (.toml or .3de)",
                    "description": "Where the circuit's parts go. Needed with a circuit.",
                    "type": "str",
                    "default_value": ""
                },
                "config": {
                    "label": "conduit config (.toml or .ini)",
                    "description": "Optional conduit or PrusaSlicer config; empty uses the settings Cura writes into the G-code.",
                    "type": "str",
                    "default_value": ""
                }
            }
        }"""

    def command(self, gcode_path):
        """The conduit command line for the G-code file at `gcode_path`."""
        args = [self.getSettingValueByKey("conduit_path") or "conduit", "postprocess", gcode_path]
        circuit = (self.getSettingValueByKey("circuit") or "").strip()
        placement = (self.getSettingValueByKey("placement") or "").strip()
        config = (self.getSettingValueByKey("config") or "").strip()
        if circuit or placement:
            args += ["--circuit", circuit, "--placement", placement]
        if config:
            args += ["-c", config]
        return args

    def execute(self, data):
        """Runs conduit on the G-code of `data` (Cura's list of G-code chunks, one per layer after
        the header) and returns the edited chunks. Raises RuntimeError with conduit's message when
        conduit fails, so Cura does not save G-code without the requested circuit."""
        original = "".join(data)
        handle, path = tempfile.mkstemp(prefix="conduit-cura-", suffix=".gcode")
        try:
            with os.fdopen(handle, "w", encoding="utf-8", newline="") as f:
                f.write(original)
            result = subprocess.run(self.command(path), capture_output=True, text=True)
            if result.returncode != 0:
                message = result.stderr.strip() or "exit code %d" % result.returncode
                raise RuntimeError("conduit postprocess failed: " + message)
            with open(path, "r", encoding="utf-8", newline="") as f:
                edited = f.read()
        finally:
            try:
                os.remove(path)
            except OSError:
                pass
        if edited == original:
            return data
        return split_like(edited, data)


def split_like(text, chunks):
    """Cuts `text` into as many pieces as `chunks`, at the first lines of chunks 1.. found in
    order (conduit adds and removes lines inside layers, never the first line of one); when a
    first line cannot be found, at Cura's `;LAYER:` comments instead."""
    starts = [0]
    position = 0
    for chunk in chunks[1:]:
        first_line = chunk.split("\n", 1)[0]
        if not first_line:
            break
        at = find_line(text, first_line, position)
        if at < 0:
            break
        starts.append(at)
        position = at + 1
    else:
        return [text[a:b] for a, b in zip(starts, starts[1:] + [len(text)])]
    pieces = []
    current = []
    for line in text.splitlines(keepends=True):
        if line.startswith(";LAYER:") and current:
            pieces.append("".join(current))
            current = []
        current.append(line)
    if current:
        pieces.append("".join(current))
    return pieces


def find_line(text, line, start):
    """Index of the first occurrence of `line` as a whole line of `text` at or after `start`."""
    at = start
    while True:
        at = text.find(line, at)
        if at < 0:
            return -1
        begins = at == 0 or text[at - 1] == "\n"
        end = at + len(line)
        ends = end == len(text) or text[end] in "\r\n"
        if begins and ends:
            return at
        at += 1
