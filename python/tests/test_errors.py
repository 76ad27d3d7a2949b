"""seam's errors as exceptions: the class, the C status code, what and where, the help."""

import pathlib
import re

import numpy as np
import pytest

import seam
from skfem_two_boxes import SKFEM_OF_EXODUS, TwoBoxes

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def host():
    return TwoBoxes(n_a=2, n_b=3)


def test_version_is_the_crate_version():
    cargo = (ROOT / "Cargo.toml").read_text()
    assert seam.__version__ == re.search(r'^version = "(.+)"', cargo, re.M).group(1)


def test_codes_are_the_c_api_status_codes():
    header = (ROOT / "include" / "seam.h").read_text()
    defined = dict(re.findall(r"#define (SEAM_(?:ERR_\w+|CUTBACK)) (\d+)", header))
    classes = {
        "SEAM_ERR_MESH": seam.MeshError,
        "SEAM_ERR_DECK": seam.DeckError,
        "SEAM_ERR_ARGUMENT": seam.ArgumentError,
        "SEAM_ERR_ORDER": seam.OrderError,
        "SEAM_ERR_ENFORCEMENT": seam.EnforcementError,
        "SEAM_ERR_INTERNAL": seam.InternalError,
        "SEAM_ERR_PLUGIN": seam.PluginError,
        "SEAM_CUTBACK": seam.CutbackError,
        "SEAM_ERR_NOTHING_PAIRED": seam.NothingPairedError,
        "SEAM_ERR_OTHER_RANK": seam.OtherRankError,
    }
    assert set(defined) - {"SEAM_ERR_NULL_ARGUMENT"} == set(classes)
    for name, cls in classes.items():
        assert cls.code == int(defined[name]), name
        assert issubclass(cls, seam.SeamError)


def test_side_zero_is_told_sides_are_one_based(host):
    b = seam.Builder(host.coords).block("a", "hex8", host.parts[0][0].t[SKFEM_OF_EXODUS].T, 1.0)
    b.side_set("top", [0, 1], [6, 0]).dofs(np.arange(host.n))
    with pytest.raises(seam.MeshError) as e:
        b.build()
    assert e.value.code == 2
    assert "surface `top`, face 1: element 1 has no side 0" in e.value.message
    assert "add 1 to 0-based side numbers" in e.value.help


def test_scikit_fem_node_order_is_an_inverted_element(host):
    b = seam.Builder(host.coords).block("a", "hex8", host.parts[0][0].t.T, 1.0)
    with pytest.raises(seam.MeshError, match="element 0 in a is (inverted|tangled)"):
        b.dofs(np.arange(host.n)).build()


def test_wrong_array_shape_names_the_argument(host):
    with pytest.raises(seam.ArgumentError, match=r"connectivity of block `a` has shape \[\d+, 4\]"):
        seam.Builder(host.coords).block("a", "hex8", np.zeros((3, 4), dtype=int), 1.0)
    with pytest.raises(seam.ArgumentError, match="unknown topology `hexa27`"):
        seam.Builder(host.coords).block("a", "hexa27", np.zeros((3, 8), dtype=int), 1.0)


def test_unknown_surface_has_a_did_you_mean(host):
    e = host.embedding()
    with pytest.raises(seam.ArgumentError) as err:
        e.add_interaction("a_tpo", "b_bottom", "tied_nitsche")
    assert err.value.code == 4
    assert "unknown surface `a_tpo`" in str(err.value)
    assert "a_top" in err.value.help


def test_evaluate_before_search_is_out_of_order(host):
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", "gap_conductance", h=10.0)
    with pytest.raises(seam.OrderError) as err:
        e.evaluate(np.zeros(host.n))
    assert err.value.code == 5
    assert "search()" in err.value.help


def test_deck_errors_carry_their_codes(host):
    e = host.embedding()
    with pytest.raises(seam.DeckError) as err:
        e.add_deck("begin contact definition x\n  contact surface s contains nowhere\n  bogus line\nend\n")
    assert err.value.code == 3
    assert err.value.diagnostic_codes and all(re.fullmatch(r"E\d{4}", c) for c in err.value.diagnostic_codes)
    assert "deck:" in str(err.value)


def test_surfaces_apart_pair_nothing_unless_allowed(host):
    moved = host.coords.copy()
    moved[host.offset_b :, 2] += 10.0
    e = host.embedding()
    e.move_nodes(moved)
    e.add_interaction("a_top", "b_bottom", "gap_conductance", h=10.0)
    with pytest.raises(seam.NothingPairedError) as err:
        e.search()
    assert err.value.code == 10
    e.allow_unpaired(0)
    e.search()
    assert e.coverage(0).paired_points == 0
    assert set(e.coverage(0).unpaired_reasons) <= {"no_face", "too_far"}
    assert e.heat(np.ones(host.n))[0].side_a == 0.0


def test_a_raising_callback_is_the_cause_of_the_enforcement_error(host):
    e = host.embedding()

    def h_of(state):
        return 1.0 / (state.temp_a - state.temp_a)

    e.add_interaction("a_top", "b_bottom", "gap_conductance", conductance=h_of)
    e.search()
    with pytest.raises(seam.EnforcementError) as err:
        e.evaluate(np.zeros(host.n))
    assert err.value.code == 6
    assert "h_of" in str(err.value)
    assert isinstance(err.value.__cause__, ZeroDivisionError)


@pytest.mark.parametrize("answer", [float("nan"), -1.0, "high", (1.0, 2.0)])
def test_a_callback_answer_that_is_no_conductance_is_refused(host, answer):
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", "gap_conductance", conductance=lambda s: answer)
    e.search()
    with pytest.raises(seam.EnforcementError):
        e.evaluate(np.zeros(host.n))


def test_quarantine_keeps_the_failing_points(host):
    e = host.embedding()

    def h_of(state):
        if state.x[0] > 0.5:
            raise ValueError("no data past x = 0.5")
        return 100.0

    e.add_interaction("a_top", "b_bottom", "gap_conductance", conductance=h_of, quarantine=True)
    e.search()
    e.evaluate(np.zeros(host.n))
    kept = e.quarantined(0)
    assert kept and all(x[0] > 0.5 and "no data past" in why for x, why in kept)
