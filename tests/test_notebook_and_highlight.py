"""A Result shows itself in Jupyter (summary and phase portrait), and Pygments knows the
`fsl` lexer through the installed entry point."""
import base64
from pathlib import Path

import pytest
from pygments.lexers import get_lexer_by_name, get_lexer_for_filename
from pygments.token import Error, Keyword, Name

import fossil_dsl

ROOT = Path(__file__).resolve().parents[1]
SPECS = sorted((ROOT / "specs").rglob("*.fsl"))


def test_a_result_displays_its_summary_and_portrait_in_a_notebook():
    result = fossil_dsl.synthesise(fossil_dsl.load(ROOT / "specs" / "safety_continuous.fsl"),
                                   seed=0)
    page = result._repr_html_()
    assert "<pre>" in page and "CERTIFIED" in page and "guarantee:" in page
    picture = page.split('src="data:image/png;base64,')[1].split('"')[0]
    assert base64.b64decode(picture).startswith(b"\x89PNG")


def test_the_fsl_lexer_is_registered_for_the_name_and_the_suffix():
    assert get_lexer_by_name("fsl").name == "FSL"
    assert get_lexer_for_filename("spec.fsl").name == "FSL"


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.name)
def test_every_bundled_spec_lexes_without_errors(path):
    tokens = list(get_lexer_by_name("fsl").get_tokens(path.read_text()))
    assert not [value for kind, value in tokens if kind is Error]
    kinds = {kind for kind, _ in tokens}
    assert Keyword in kinds and Name in kinds
