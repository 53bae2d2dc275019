"""The zoo as the one registry of buildable models: the generic components, the TSFM types a
TOML description names, sweeps and ``gripkit zoo`` all resolve their names in it."""

import json
import math
import warnings

import numpy as np
import pytest

from gripkit import zoo
from gripkit.batch.scenarios import build_model
from gripkit.cli import main
from gripkit.description import load_description
from gripkit.errors import ArgumentError, ConfigError
from gripkit.models import BoucWen, MassSpringDamper, PiezoActuator
from gripkit.systems.tsfm.parameters import TABLE_II
from gripkit.zoo import registry

# every name the description's and the sweeps' own registries held before the zoo became the one
FORMER = ("mass-spring-damper", "bouc-wen", "piezo-actuator", "tsfm-finger", "tsfm-finger-contact",
          "tsfm-gripper")


def _quiet_build(name, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return zoo.build(name, **kw)


def test_every_former_name_is_one_zoo_entry(capsys):
    names = [e.name for e in zoo.entries()]
    assert len(names) == len(set(names))
    assert all(names.count(n) == 1 for n in FORMER)
    assert main(["zoo", "list", "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)["models"]}
    assert {n: rows[n]["system"] for n in FORMER[:3]} == dict.fromkeys(FORMER[:3], "generic")


@pytest.mark.parametrize("name, cls", [("mass-spring-damper", MassSpringDamper),
                                       ("bouc-wen", BoucWen), ("piezo-actuator", PiezoActuator)])
def test_generic_entries_carry_the_components_values_with_a_source(name, cls):
    m = zoo.build(name)
    assert type(m) is cls
    np.testing.assert_array_equal(m.theta(), cls(check=False).theta())  # the components' defaults
    assert all(p.source for p in m.parameters.values())


def test_generic_values_are_table_ii_left_finger():
    """Bouc-Wen and piezo values: 001_0b92a7da96e7aa46.txt Table II, left finger (SI)."""
    left = TABLE_II["left"]
    for name in ("bouc-wen", "piezo-actuator"):
        p = zoo.build(name).parameters
        for n in p.names:
            if n == "L_a":
                assert p.value(n) == 15e-3 and p[n].source.startswith("assumed")
            else:
                assert p.value(n) == left[n] and "Table II, left finger" in p[n].source


def test_mass_spring_damper_entry_is_the_stated_oscillator():
    """m = 1 kg, k = 1 N/m, b = 0.1 N·s/m: f_n = 1/(2π) Hz, ζ = b/(2√(km)) = 0.05."""
    m = zoo.build("mass-spring-damper")
    assert m.natural_frequency_hz() == pytest.approx(1 / (2 * math.pi), rel=1e-15)
    assert m.damping_ratio() == pytest.approx(0.05, rel=1e-15)


def test_finger_contact_entry_is_fig13():
    """x_w = 62.42 µm (§V-C) with Table III's 72.5 N/m part: under the Fig. 13 sine (0-50 V,
    0.1 Hz) the left finger first touches the part at 44 V (§V-C)."""
    m = _quiet_build("tsfm-finger-contact")
    p = m.parameters
    assert p.value("x_w") == 62.42e-6 and "§V-C" in p["x_w"].source
    assert p.value("k_e") == 72.5 and "Table III" in p["k_e"].source
    dt = 5e-5
    t = np.arange(int(10 / dt)) * dt
    U = 25.0 - 25.0 * np.cos(2 * np.pi * 0.1 * t)
    tr = m.simulate(U, dt=dt)
    on = np.flatnonzero(tr["contact"] > 0.5)
    assert abs(U[on[0]] - 44.0) < 0.2
    right = _quiet_build("tsfm-finger", side="right")
    assert right.parameters.value("k_s") == TABLE_II["right"]["k_s"]


def test_description_types_build_through_the_zoo(tmp_path):
    """A bouc-wen and a free piezo-actuator (loads = false) described in TOML simulate as the
    Python components do."""
    body = ("[simulation]\nfs = 1000\nduration = 0.5\n"
            "[inputs.U]\nkind = \"sine\"\namplitude = 50.0\nfrequency = 2.0\n")
    for mtype, extra, ref in [("bouc-wen", "", BoucWen()),
                              ("piezo-actuator", "loads = false\n", PiezoActuator(loads=False))]:
        p = tmp_path / f"{mtype}.toml"
        p.write_text(f"[model]\ntype = \"{mtype}\"\n{extra}{body}")
        d = load_description(p)
        assert [s.name for s in d.model.inputs] == ["U"]
        out = d.model.simulate(d.inputs)
        ref_out = ref.simulate(d.inputs["U"], dt=1e-3)
        np.testing.assert_array_equal(out[ref.outputs[0].name], ref_out[ref.outputs[0].name])


def test_unknown_type_lists_the_zoo(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[model]\ntype = \"piano\"\n[simulation]\nfs = 10\nduration = 1\n")
    with pytest.raises(ConfigError, match="type = 'piano' is unknown") as e:
        load_description(p)
    assert "mass-spring-damper" in e.value.hint and "ftg100-plant" in e.value.hint
    p.write_text("[model]\ntype = \"amadeus-hand\"\n[simulation]\nfs = 10\nduration = 1\n")
    with pytest.raises(ConfigError, match="zoo model 'amadeus-hand' cannot be simulated"):
        load_description(p)


def test_sweeps_resolve_models_in_the_zoo():
    m = build_model("mass-spring-damper")
    assert isinstance(m, MassSpringDamper) and "illustrative" in m.parameters["k"].source
    with pytest.raises(ConfigError, match="unknown model 'msd'") as e:
        build_model("msd")
    assert "registered (the zoo)" in e.value.hint and "bouc-wen" in e.value.hint


def test_register_adds_a_name_every_front_end_sees(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "_ENTRIES", registry._ENTRIES)  # restored after the test
    zoo.register(zoo.ZooEntry("my-oscillator", "mine", "an MSD under my name", "",
                              "gripkit.models.reference:reference_mass_spring_damper"))
    assert type(zoo.build("my-oscillator")) is MassSpringDamper
    assert isinstance(build_model("my-oscillator"), MassSpringDamper)
    p = tmp_path / "mine.toml"
    p.write_text("[model]\ntype = \"my-oscillator\"\n[simulation]\nfs = 10\nduration = 1\n"
                 "[inputs.F]\nkind = \"constant\"\nvalue = 1.0\n")
    assert load_description(p).model.name == "mass-spring-damper"
    with pytest.raises(ArgumentError, match="the name 'bouc-wen' is taken"):
        zoo.register(zoo.ZooEntry("bouc-wen", "mine", "", "",
                                  "gripkit.models.reference:reference_bouc_wen"))
    with pytest.raises(ArgumentError, match="factory must be 'module:function'"):
        zoo.register(zoo.ZooEntry("other", "mine", "", "", "gripkit.models.reference.bouc_wen"))
