"""`fossil_dsl.load_result(DIR)`: nothing in the folder is trusted; the kernel judges the
loaded claim again."""
import json
from pathlib import Path

import pytest

import fossil_dsl

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    folder = tmp_path_factory.mktemp("run")
    result = fossil_dsl.synthesise(fossil_dsl.load(ROOT / "specs" / "stability_controlled.fsl"),
                                   seed=0)
    assert result.certified, result.reason
    result.save(folder)
    return result, folder


def test_an_edited_formula_is_judged_on_what_the_folder_holds(saved, tmp_path):
    _, folder = saved
    data = json.loads((folder / "result.json").read_text())
    data["functions"]["V"] = "x0^2 - x1^2"  # not a Lyapunov function
    (tmp_path / "result.json").write_text(json.dumps(data))
    loaded = fossil_dsl.load_result(tmp_path)
    assert not loaded.certified and "V" in loaded.reason


def test_without_judging_nothing_is_certified(saved):
    _, folder = saved
    quick = fossil_dsl.load_result(folder, judge_again=False)
    assert not quick.certified and "judge_again=False" in quick.reason
    assert quick.formulas == saved[0].formulas


def test_a_folder_without_a_result_is_a_load_error(tmp_path):
    with pytest.raises(fossil_dsl.LoadError):
        fossil_dsl.load_result(tmp_path)
    (tmp_path / "result.json").write_text("{not json")
    with pytest.raises(fossil_dsl.LoadError):
        fossil_dsl.load_result(tmp_path)
