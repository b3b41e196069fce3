"""The documentation site: Sphinx with the Furo theme, pages in Markdown (MyST).

Sphinx because autodoc reads the plug-in protocols' docstrings from the code itself, `-W` makes every broken
link, missing page or unknown anchor fail the build, and MyST reads the Markdown the docs were written in.
The command and YAML references are generated from the parser and the models at each build (_ext/reference.py).
Build: sphinx-build -W --keep-going -b html docs docs/_build/html"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

from accelcal_rig import __version__  # noqa: E402 - after the path to the local extensions

project = "accelcal-rig"
author = "the accelcal-rig developers"
copyright = "2026, the accelcal-rig developers"  # noqa: A001 - Sphinx's name for it
version = release = __version__

extensions = ["myst_parser", "sphinx.ext.autodoc", "reference"]
source_suffix = {".md": "markdown"}
exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store"]
# Every heading up to level 4 is a link target, as on GitHub (docs link to sections as page.md#section).
myst_heading_anchors = 4
myst_enable_extensions = ["colon_fence", "deflist"]
suppress_warnings = ["myst.header"]  # a page may start below level 1 where it includes another

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}


def _plain_docstring(app, what, name, obj, options, lines):  # noqa: ANN001 - Sphinx's event signature
    """The code's docstrings are plain prose, not reStructuredText: |g|, `**` and a word ending in `_` mean
    nothing to Sphinx, so they are escaped before autodoc parses them."""
    for index, line in enumerate(lines):
        line = line.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*")
        lines[index] = re.sub(r"(\w)_(?=\W|$)", r"\1\\_", line)


def setup(app):  # noqa: ANN001, ANN201 - Sphinx's
    app.connect("autodoc-process-docstring", _plain_docstring)


html_theme = "furo"
html_title = f"accelcal-rig {__version__}"
html_show_sourcelink = False
nitpicky = False
