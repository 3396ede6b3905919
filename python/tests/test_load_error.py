"""Load-time errors reach Python as one type, gauss6.LoadError (a ValueError), with the C++ message."""
from __future__ import annotations

import pytest

import gauss6
from gauss6 import _gauss6


def test_one_python_type_for_every_reader(tmp_path):
    assert issubclass(gauss6.LoadError, ValueError)
    # The readers' old names stay importable and are the same type.
    assert gauss6.SceneError is gauss6.LoadError and gauss6.MeshFileError is gauss6.LoadError
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    with pytest.raises(gauss6.LoadError) as e:
        gauss6.read_mesh(str(empty))
    assert str(e.value) == f"{empty}: the file is empty"
    bad_json = tmp_path / "bad.json"
    bad_json.write_text('{\n"format": ')
    with pytest.raises(gauss6.LoadError, match=r"bad\.json:2: not valid JSON"):
        _gauss6.read_qp_instances(str(bad_json))
    scene = tmp_path / "s.toml"
    scene.write_text('format = "gauss6-scene"\nversion = 1\nname = "x"\nbogus = 1\n')
    with pytest.raises(gauss6.LoadError) as e:
        _gauss6.load_scene(str(scene))
    assert str(e.value).startswith(f"{scene}:4:1: bogus: unknown key")
