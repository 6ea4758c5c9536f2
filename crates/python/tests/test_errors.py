"""Bad input raises an exception of the module with the command line's message; the
interpreter never crashes."""

import math

import numpy as np
import pytest

import stickslip

BAD_JOINT = """
[model]
dofs = ["M"]
mass = [[10.0]]
stiffness = [[2.24e7]]

[[load]]
name = "shaker"
dof = "M"

[[joint]]
name = "joint"
law = "jenkins"
dof = "M"
threshold = -3.0

[excitation]
levels = [1000.0]

[sweep]
start_hz = 150.0
end_hz = 350.0
"""


def small_study():
    return {
        "model": {"dofs": ["M"], "mass": [[10.0]], "stiffness": [[2.24e7]]},
        "damping": {"alpha": 35.0},
        "load": [{"name": "shaker", "dof": "M"}],
        "joint": [{"name": "joint", "law": "jenkins", "dof": "M", "stiffness": 8.11e6,
                   "replaces_stiffness": True, "threshold": 1000.0}],
        "excitation": {"levels": [1000.0]},
        "sweep": {"start_hz": 150.0, "end_hz": 350.0},
        "output": [{"name": "mass", "dof": "M"}],
    }


def test_a_bad_file_raises_the_cli_message(cli, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BAD_JOINT)
    p = cli("run", path, "--out", tmp_path / "out", "--quiet", check=False)
    assert p.returncode != 0
    with pytest.raises(stickslip.StudyError) as e:
        stickslip.Study.from_toml(path)
    # The command prints `error: <message>`; the exception carries the message itself.
    assert p.stderr.strip() == f"error: {e.value}"
    # The file's line and column of the value.
    line = path.read_text().splitlines().index("threshold = -3.0") + 1
    assert str(e.value) == f'{path}:{line}:13: [[joint]] "joint": threshold must be > 0 N, got -3'


def test_a_bad_dict_raises_the_same_message_without_a_line():
    d = small_study()
    d["joint"][0]["threshold"] = -3.0
    with pytest.raises(stickslip.StudyError) as e:
        stickslip.Study.from_dict(d)
    assert str(e.value) == '<dict>: [[joint]] "joint": threshold must be > 0 N, got -3'


@pytest.mark.parametrize("change, message", [
    (lambda d: d["joint"][0].update(thresold=1.0), "unknown field `thresold`"),
    (lambda d: d["damping"].update(alpha=math.nan), "[damping]: alpha must be >= 0 1/s, got NaN"),
    (lambda d: d["sweep"].update(start_hz="150"), "invalid type: string \"150\", expected f64"),
    (lambda d: d.pop("sweep"), "missing field `sweep`"),
])
def test_bad_dicts_name_the_key(change, message):
    d = small_study()
    change(d)
    with pytest.raises(stickslip.StudyError, match=None) as e:
        stickslip.Study.from_dict(d)
    assert message in str(e.value)


def test_values_python_cannot_put_in_a_study_name_their_place():
    d = small_study()
    d["damping"]["alpha"] = None
    with pytest.raises(stickslip.InputError) as e:
        stickslip.Study.from_dict(d)
    assert str(e.value) == "damping.alpha: None is not a value (leave the key out for its default)"
    d = small_study()
    d["model"]["mass"] = np.array([["a"]])
    with pytest.raises(stickslip.InputError, match=r"model.mass: a NumPy value of dtype <U1 is not a number"):
        stickslip.Study.from_dict(d)


def test_numpy_values_go_in_as_numbers():
    d = small_study()
    d["model"]["mass"] = np.array([[10.0]])
    d["excitation"]["levels"] = [np.float64(1000.0)]
    d["harmonic_balance"] = {"harmonics": np.int64(5), "samples": 128}
    study = stickslip.Study.from_dict(d)
    assert study.to_dict()["harmonic_balance"]["harmonics"] == 5
    assert study.levels == [1000.0]


def test_modes_refuse_wrong_dtypes_shapes_and_nan():
    k = np.array([[2.0, -1.0], [-1.0, 2.0]])
    with pytest.raises(stickslip.InputError, match="mass: expected a 2-D float64 array, got an array of dtype int64"):
        stickslip.modes(np.eye(2, dtype=np.int64), k)
    with pytest.raises(stickslip.InputError, match=r"stiffness: expected a square 2x2 array"):
        stickslip.modes(np.eye(2), np.ones((2, 3)))
    with pytest.raises(stickslip.InputError, match="mass: expected a 2-D float64 array, got a list"):
        stickslip.modes([[1.0]], k)
    bad = k.copy()
    bad[0, 1] = np.nan
    with pytest.raises(stickslip.InputError, match="finite|NaN"):
        stickslip.modes(np.eye(2), bad)


def test_extract_refuses_nan_and_unequal_lengths():
    t = np.arange(1000) / 1000.0
    ref = np.cos(2 * np.pi * 10 * t)
    with pytest.raises(stickslip.InputError, match=r"responses\[\"a\"\]: expected a 1-D float64 array"):
        stickslip.extract(ref, {"a": np.zeros((2, 2))}, 1000.0)
    r = ref.copy()
    r[5] = np.nan
    with pytest.raises(stickslip.InputError, match="reference: sample 5 is NaN"):
        stickslip.extract(r, {}, 1000.0)
    with pytest.raises(stickslip.SolveError, match="a"):
        stickslip.extract(ref, {"a": ref[:10].copy()}, 1000.0)
