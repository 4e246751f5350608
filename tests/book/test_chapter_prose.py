"""The chapters' prose states the verdict rule once: where a chapter mentions the book's one rule it links to
its definition on the landing page (``navlib.verdicts.VERDICT_DEFINITIONS``) instead of restating it, so a
change of the rule cannot leave a chapter describing an older one."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("*.ipynb"))
#: Phrases that define a verdict in words (a restated rule).
DEFINING = re.compile(
    r"(not reproduced|reproduced|cannot be judged)\*?\s+when\s+(it|the|our|its)\b", re.I
)


def _markdown(path: Path) -> list[tuple[int, str]]:
    nb = json.loads(path.read_text(encoding="utf-8"))
    return [
        (i, "".join(c["source"])) for i, c in enumerate(nb["cells"]) if c["cell_type"] == "markdown"
    ]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_chapters_link_the_one_rule_and_do_not_restate_it(path):
    for i, text in _markdown(path):
        flat = " ".join(text.split())
        assert not DEFINING.search(flat), f"{path.name}, cell {i}: restates the verdict rule"
        if "book's one rule" in flat:
            assert "(what-the-verdicts-mean)" in flat, f"{path.name}, cell {i}: link the rule"


def test_the_check_finds_a_restated_rule():
    old = (
        "Each verdict follows the book's one rule (`navlib.verdicts`): a claim is reproduced when the "
        "95 % interval lies wholly on the paper's side"
    )
    assert DEFINING.search(old)
