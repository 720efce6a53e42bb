"""The README's "From Python" example runs as written."""

import re

from conftest import ROOT


def test_readme_python_example_runs():
    text = (ROOT / "README.md").read_text()
    sec = text.split("## From Python", 1)
    assert len(sec) == 2, "README has no 'From Python' section"
    blocks = re.findall(r"```python\n(.*?)```", sec[1], re.S)
    assert blocks, "no python block in the From Python section"
    code = blocks[0]
    assert len(code.strip().splitlines()) <= 12
    exec(compile(code, "README.md", "exec"), {"__name__": "__readme__"})
