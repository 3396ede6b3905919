"""The documented defaults are the code's: README.md's table of projection settings and the
"default" comments of docs/scene-format.md are compared with gauss6.defaults(), which reads
the C++ structs, so the documents cannot drift from the code again."""
from __future__ import annotations

import re

import pytest

import gauss6
from gauss6 import paths

ROOT = paths.DATASETS_DIR.parent


def _value(text: str):
    """A documented default as Python: true/false, a number, or a quoted string."""
    text = text.strip().strip("`")
    if text in ("true", "false"):
        return text == "true"
    if text.startswith('"'):
        return text.strip('"')
    return float(text)


def readme_projection_table() -> dict:
    """{setting: default} from README.md's `| setting | default | meaning |` table."""
    lines = (ROOT / "README.md").read_text().splitlines()
    start = lines.index("| setting | default | meaning |")
    table = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        name, default = [c.strip() for c in line.strip("|").split("|")][:2]
        table[name.strip("`")] = _value(default)
    return table


def scene_format_defaults() -> dict:
    """{"section.key": default} from the `# optional, default X` comments of docs/scene-format.md."""
    out, section = {}, ""
    for line in (ROOT / "docs" / "scene-format.md").read_text().splitlines():
        if m := re.match(r"\[+(\w+)\]+", line):
            section = m.group(1)
        m = re.match(r"(\w+)\s*=.*#\s*optional, default (.+?)(?::|;|$)", line)
        if m:
            out[f"{section}.{m.group(1)}"] = m.group(2).strip()
        m = re.match(r"\[(\w+)\]\s*#\s*optional; default (\w+) = (\S+)", line)
        if m:
            out[f"{m.group(1)}.{m.group(2)}"] = m.group(3)
    return out


def test_readme_projection_defaults_are_the_code_s():
    code = gauss6.defaults()["projection"]
    assert readme_projection_table() == code


def test_scene_format_defaults_are_the_code_s():
    d = gauss6.defaults()
    doc = scene_format_defaults()
    number = r"([-+0-9.e]+)"

    def num(key: str, unit: str = "") -> float:
        m = re.fullmatch(number + (r"\s*" + re.escape(unit) if unit else ""), doc[key])
        assert m, f"{key}: cannot read the default {doc[key]!r}"
        return float(m.group(1))

    m = re.fullmatch(number + r"\s*\*\s*delta", doc["contact.offset_eps"])
    assert m and float(m.group(1)) == d["contact"]["offset_eps_per_delta"]
    assert num("contact.offset_time", "s") == d["contact"]["offset_time"]
    assert num("device.rate_hz") == d["device"]["rate_hz"]
    assert num("device.max_force", "N") == d["device"]["max_force"]
    assert num("device.max_torque", "N m") == d["device"]["max_torque"]
    assert _value(doc["surface.kind"]) == d["surface"]["kind"]


def test_trace_errors_are_load_errors(tmp_path):
    """Both trace readers' errors belong to the one load-error hierarchy (load_error.h)."""
    import gauss6
    from gauss6.trace import TraceFormatError, read_trace
    assert issubclass(gauss6._gauss6.device.TraceError, gauss6.LoadError)
    assert issubclass(TraceFormatError, gauss6.LoadError) and issubclass(TraceFormatError, ValueError)
    bad = tmp_path / "bad.g6trace"
    bad.write_bytes(b"not a trace")
    with pytest.raises(gauss6.LoadError, match="bad.g6trace"):
        read_trace(bad)
