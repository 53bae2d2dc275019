"""``gripkit identify hysteresis`` and ``gripkit identify bouc-wen`` (issue 23): each command's
``--help`` description says in one sentence how it differs from the other and when to use which,
and docs/sysid.md carries the same two sentences."""

import re
from pathlib import Path

import pytest

from gripkit.cli.identify_hysteresis import identify_hysteresis
from gripkit.cli.identify_tsfm import identify_bouc_wen_cmd

DOCS = Path(__file__).resolve().parents[2] / "docs" / "sysid.md"


def _words(text: str) -> str:
    return " ".join(text.replace("`", "").split())


def _which_sentence(command) -> str:
    """The description's sentence that names the other command: '…: use it …; … identify …'."""
    first = _words(command.__doc__.split("\n\n")[0])
    [sentence] = [s for s in re.split(r"(?<=\.) ", first) if ": use it " in s]
    return sentence


@pytest.mark.parametrize("command, other", [(identify_hysteresis, "identify bouc-wen"),
                                            (identify_bouc_wen_cmd, "identify hysteresis")])
def test_each_description_names_the_other_command_and_the_docs_say_it(command, other):
    sentence = _which_sentence(command)
    assert other in sentence
    # (in the docs after the command's name: 'The …' there reads 'the …')
    assert sentence[0].lower() + sentence[1:] in _words(DOCS.read_text())
