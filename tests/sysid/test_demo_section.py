"""The amadeus-identification demo section (the paper's §V study on simulated data) runs and
reports the seed's qualitative findings (000_8f66dcc7ab06470c.txt §V-E/F)."""

import pytest

from gripkit.report import Report


@pytest.mark.slow
def test_demo_section_reproduces_the_studys_findings(tmp_path):
    from gripkit.systems.amadeus import demo_identification as amadeus_identification

    rep = Report("test")
    s = amadeus_identification.run(rep, quick=True)
    assert s["winner_on_loss_filtered_y"] == [4, 4, 2]  # Table II: [4 4 2] has the lowest loss
    assert s["non_minimum_phase_222"] and s["zero_222"] == pytest.approx(1.167, abs=3
                                                                         * s["zero_222_std"] + 1e-3)
    assert s["minimum_phase_2210"]
    assert s["oe_validation_fit_percent"] > s["arx_validation_fit_percent"]
    path = rep.write(tmp_path)
    html = path.read_text()
    assert html.count("<img") == 5 and "INCONSISTENT" in html  # the σ(B) factor of §V-F
    assert {p.name for p in (tmp_path / "figures").iterdir()} >= {"amadeus-pole-zero.png",
                                                                  "amadeus-bode.png"}
