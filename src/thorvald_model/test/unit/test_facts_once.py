"""Each robot fact is derived once, on the configuration's types (thorvald_model.values), and read
everywhere else: no source of the workspace derives again whether a drive steers, its motors'
limits, whether a battery is fitted or which kind a passive wheel is from the raw keys."""

import glob
import os
import re

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
VALUES = os.path.join(SRC, "thorvald_model", "src", "thorvald_model", "values.py")

# what re-deriving a fact looks like, in Python and in xacro
REDERIVED = {
    "whether a drive steers": r"\bd(rive)?\.type\s*[!=]=|[!=]=\s*DRIVE_(STEERED|DIFF)\b|\['type'\]\s*[!=]=\s*[01]\b",
    "whether a battery is fitted": r"with_battery(\]|\b)\s*(and|else|\))|and\s+\w+(\.|\[')with_battery",
    "the motors' limits": r"_motor_torque'?\]?\s*\*|prp_max_rpm'?\]?\s*\*\s*2(\.0)?\s*\*\s*(math\.)?pi",
    "a passive wheel's kind": r"\['type'\]\s*==\s*'caster'|\.type\s*==\s*\"(caster|fixed)\"",
}


def sources():
    files = glob.glob(os.path.join(SRC, "*", "src", "**", "*.py"), recursive=True)
    files += glob.glob(os.path.join(SRC, "*", "urdf", "*.xacro"))
    return [f for f in files if os.path.realpath(f) != VALUES and os.sep + "thorvald_description" + os.sep not in f]


@pytest.mark.parametrize("fact", sorted(REDERIVED))
def test_no_source_derives_the_fact_again(fact):
    found = []
    for path in sources():
        with open(path) as f:
            for n, line in enumerate(f, 1):
                if re.search(REDERIVED[fact], line):
                    found.append(f"{os.path.relpath(path, SRC)}:{n}: {line.strip()}")
    assert found == [], f"{fact} derived again:\n" + "\n".join(found)


def test_the_patterns_find_what_they_look_for():
    """The checks are not vacuous: each finds the derivation values.py makes."""
    with open(VALUES) as f:
        text = f.read()
    assert re.search(REDERIVED["whether a drive steers"], "self.type == DRIVE_STEERED")
    assert re.search(REDERIVED["whether a drive steers"], "if d.type == 1:")
    assert not re.search(REDERIVED["whether a drive steers"], "if m.type == 1:")  # a TxPDO4's type
    assert re.search(REDERIVED["whether a battery is fitted"], "b['type'] == 1 and b['with_battery'] else")
    assert re.search(REDERIVED["the motors' limits"], "d['prp_motor_torque'] * d['prp_gr_rt']")
    assert re.search(REDERIVED["a passive wheel's kind"], "p['type'] == 'caster'")
    assert re.search(REDERIVED["whether a drive steers"], text) and re.search(REDERIVED["the motors' limits"], text)
