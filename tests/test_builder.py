"""The public builder: layout helpers, limbs, free chains, closures, number formatting and its errors."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import pinmob
from pinmob.builder import MechanismBuilder, cross, polar, radial, rotation, rpy, symmetric_angles, toml_value
from pinmob.builder.text import ZERO_RTOL, cleaned, vector
from pinmob.catalog.arms import ur5_path
from pinmob.exceptions import ConfigurationError
from pinmob.testing import assert_mobility

DATA = Path(__file__).resolve().parent / "data"
Z = [0.0, 0.0, 1.0]


def test_layout_helpers():
    e, t = radial(np.pi / 2)
    assert_allclose(e, [0, 1, 0], atol=1e-15)
    assert_allclose(t, [-1, 0, 0], atol=1e-15)
    assert_allclose(polar(2.0, np.pi, 0.5), [-2, 0, 0.5], atol=1e-15)
    assert_allclose(symmetric_angles(4, 0.1), [0.1, 0.1 + np.pi / 2, 0.1 + np.pi, 0.1 + 1.5 * np.pi])
    assert_allclose(rotation([0, 0, 2], np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    r = rotation([0.3, -0.2, 0.9], 0.7)
    assert_allclose(pin.rpy.rpyToMatrix(np.array(rpy(r))), r, atol=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6, allow_subnormal=False), min_size=6, max_size=6))
def test_cross_is_numpys_to_the_last_bit(xs):
    """The builder's cross product gives np.cross's numbers exactly (the same products and differences), so files
    built with it are those built with np.cross; by hand, x cross y = z and y cross x = -z."""
    a, b = np.array(xs[:3]), np.array(xs[3:])
    assert cross(a, b).tobytes() == np.cross(a, b).tobytes()
    assert cross([1, 0, 0], [0, 1, 0]).tolist() == [0.0, 0.0, 1.0]
    assert cross([0, 1, 0], [1, 0, 0]).tolist() == [0.0, 0.0, -1.0]


def test_toml_reads_its_angles_from_the_model_it_is_given():
    """A revolute at 3.5 rad is written in (-pi, pi], 3.5 - 2 pi, under the builder's limits [-pi, pi]; given the
    model of the same URDF with limits [0, 4] (which exclude 3.5 - 2 pi) it is written as 3.5, the representative
    inside them closest to 0: the angles come from the model given, not from the text parsed again."""
    b = MechanismBuilder("one")
    chain = b.chain("A")
    chain.revolute("r", at=[0, 0, 0], axis=Z)
    chain.frame("end", at=[0.1, 0, 0])
    conf = {"c": {"joints": {"A_r": 3.5}}}
    urdf = b.urdf()
    assert "A_r = -2.78318530717959" in b.toml("one.urdf", conf, urdf_text=urdf)
    wide = b.model(urdf.replace('lower="-3.14159265358979" upper="3.14159265358979"', 'lower="0" upper="4"'))
    assert "A_r = 3.5" in b.toml("one.urdf", conf, model=wide)


def test_builder_sketch_and_analyze():
    """A user's sketch: a planar 2-RRR analysed without writing files. By hand: each limb's three revolutes about z
    through non-collinear points span the planar twists {T x, T y, R z}; so do both: 2T1R."""
    b = MechanismBuilder("2-RRR", "two planar RRR limbs")
    for name, theta in zip("AB", symmetric_angles(2), strict=True):
        limb = b.limb(name)
        limb.revolute("r1", at=polar(0.3, theta), axis=Z, actuated=True)
        limb.revolute("r2", at=polar(0.2, theta + 0.5), axis=Z)
        limb.revolute("r3", at=polar(0.05, theta), axis=Z)
        limb.tip(at=[0, 0, 0])
    mech = b.mechanism()
    assert_mobility(mech, mech.neutral(), dof=3, motion_type="2T1R", directions={"T": [[1, 0, 0], [0, 1, 0]], "R": [Z]})


def four_bar() -> MechanismBuilder:
    """tests/data/fourbar (written there by its own URDF writer) with the builder: two free chains, a 6d closure."""
    b = MechanismBuilder("four-bar", "planar four-bar closed by a 6d weld")
    left = b.chain("L")
    left.revolute("crank", at=[0, 0, 0], axis=Z, actuated=True)
    left.revolute("coupler", at=[0, 0.1, 0], axis=Z)
    left.revolute("pin", at=[0.3, 0.2, 0], axis=Z)
    end_l = left.frame("end", at=[0.3, 0.2, 0])
    right = b.chain("R")
    right.revolute("rocker", at=[0.3, 0, 0], axis=Z)
    end_r = right.frame("end", at=[0.3, 0.2, 0])
    b.closure("B", end_l, end_r, "6d")
    return b


def test_builder_expresses_the_test_data_four_bar(tmp_path):
    """Free chains, frames and closures: the builder's four-bar has the same joints (placements, axes) and closure
    frames as tests/data/fourbar.urdf, and the mobility derived by hand: 4 joint rates, a 6d weld (6 rows):
    Grubler 4 - 6 = -2, but a planar loop has only 3 independent closure rows: DoF 1, 3 redundant."""
    mine = pinmob.load(four_bar().write(tmp_path, "fourbar", {"home": {"joints": {}}}))
    theirs = pinmob.load(DATA / "fourbar.toml")
    assert mine.model.nv == theirs.model.nv == 4 and mine.platform == ""
    for j in range(1, 5):
        assert mine.model.joints[j].shortname() == theirs.model.joints[j].shortname() == "JointModelRZ"
    placements = sorted(tuple(mine.model.jointPlacements[j].translation) for j in range(1, 5))
    assert placements == sorted(tuple(theirs.model.jointPlacements[j].translation) for j in range(1, 5))
    data = mine.model.createData()
    pin.framesForwardKinematics(mine.model, data, mine.neutral())
    for frame in ("L_end", "R_end"):
        assert_allclose(data.oMf[mine.model.getFrameId(frame)].translation, [0.3, 0.2, 0], atol=1e-15)
    mm = pinmob.analyze_mechanism(mine, "home")
    assert (mm.mechanism_dof, mm.grubler, mm.redundant_constraints) == (1, -2, 3)
    assert mine.actuated == ("L_crank",)


def test_limb_branch_closure_and_top_level_actuation(tmp_path):
    """A limb with a branch closed to its own tip body (the Delta's parallelogram pattern) writes the branch's
    joints outside the limb, its actuated joints at the top level and the closure in [[closures]]."""
    b = MechanismBuilder("branchy")
    limb = b.limb("A")
    limb.revolute("r", at=[0, 0, 0], axis=Z, actuated=True)
    side = limb.branch("b")
    side.revolute("s", at=[0.1, 0, 0], axis=Z, actuated=True)
    end = side.frame("end", at=[0.2, 0, 0])
    limb.revolute("t", at=[0.2, 0.1, 0], axis=Z)
    pf = limb.frame("pf", at=[0.2, 0, 0])
    limb.tip(at=[0.2, 0.1, 0])
    b.closure("loop", pf, end, "revolute", axis=Z)
    text = b.toml("x.urdf")
    assert 'actuated = ["A_b_s"]' in text and '[[closures]]\nname = "loop"' in text and "axis = [0.0, 0.0, 1.0]" in text
    mech = b.mechanism()
    assert mech.limbs[0].joints == ("A_r", "A_t") and mech.actuated == ("A_r", "A_b_s")
    assert [c.name for c in mech.closures] == ["loop"]


def test_urdf_limb_errors():
    ur5 = ur5_path()
    b = MechanismBuilder("arm")
    with pytest.raises(ConfigurationError, match="no link 'nope' in ur5_robot.urdf; valid: .*tool0"):
        b.urdf_limb("A", ur5, "base_link", "nope", (np.eye(3), [0, 0, 0]))
    with pytest.raises(ConfigurationError, match="not in the chain"):
        b.urdf_limb("A", ur5, "base_link", "tool0", (np.eye(3), [0, 0, 0]), actuated=["elbow"])
    with pytest.raises(ConfigurationError, match="base_pose: not a rotation matrix"):
        b.urdf_limb("A", ur5, "base_link", "tool0", (2 * np.eye(3), [0, 0, 0]))
    limb = b.urdf_limb("A", ur5, "base_link", "tool0", (np.eye(3), [0, 0, 0]), actuated=["elbow_joint"])
    assert limb.joints[0] == "A_shoulder_pan_joint" and limb.actuated == ["A_elbow_joint"]


# --------------------------------------------------------------------------- errors


def one_limb(name: str = "m") -> MechanismBuilder:
    b = MechanismBuilder(name)
    b.limb("A").revolute("r", at=[0, 0, 0], axis=Z)
    return b


@pytest.mark.parametrize(
    "build,message",
    [
        (lambda: MechanismBuilder("empty").urdf(), "is empty: add a limb"),
        (lambda: MechanismBuilder("x").limb("A<B>"), "'A<B>' is not a valid name"),
        (lambda: one_limb().limbs[0].revolute("a&b", at=[0, 0, 0], axis=Z), "'a&b' is not a valid name"),
        (lambda: one_limb().limbs[0].tip(at=[0, 0, 0], rotation=np.diag([1.0, 1.0, -1.0])), "det R = -1"),
        (lambda: one_limb().limbs[0].tip(at=[0, 0, 0], rotation=2 * np.eye(3)), "not a rotation matrix"),
        (lambda: one_limb().limbs[0].universal("u", [0, 0, 0], [1, 0, 0], [-2, 0, 0]), "are parallel"),
        (lambda: one_limb().limbs[0].spherical("s", [0, 0, 0], ([1, 0, 0], [0, 1, 0], [1, 1, 0])), "dependent"),
        (lambda: one_limb().limbs[0].revolute("q", [0, 0, 0], Z, lower=1.0, upper=-1.0), "lower <= upper"),
        (lambda: one_limb().limbs[0].revolute("q", [0, 0, 0], [0, 0, 0]), "axis must be a non-zero 3-vector"),
        (lambda: one_limb().limbs[0].prismatic("q", [0, np.nan, 0], Z), "must be a finite 3-vector"),
        (lambda: one_limb().closure("c", "A_r_link", "base", "hinge"), "unknown type 'hinge'"),
        (lambda: one_limb().chain("C", parent="nowhere"), "no link 'nowhere'; valid: 'A_r_link', 'base'"),
        (lambda: toml_value(float("nan")), "must be finite"),
        (lambda: toml_value(float("inf")), "must be finite"),
        (lambda: toml_value(object()), "cannot write a object"),
    ],
)
def test_builder_errors_are_clear(build, message):
    with pytest.raises(ConfigurationError, match=message):
        build()


def test_tips_must_coincide_at_the_reference():
    b = MechanismBuilder("split")
    for name, x in (("A", 0.0), ("B", 0.2)):
        limb = b.limb(name)
        limb.revolute("r", at=[x, 0, 0], axis=Z)
        limb.tip(at=[x, 0.1, 0])
    with pytest.raises(ConfigurationError, match="limb 'B' tip is 0.2 m and 0 .* away from limb 'A' tip"):
        b.urdf()


def test_tips_of_a_mechanism_drawn_at_its_centre_coincide_up_to_round_off():
    """Every joint and tip at the origin (a spherical 3-RRR drawn at its centre): a tip 1e-17 m off, the round-off
    of a computed position, coincides (the old rule, relative to the joints' 0 m, asked for 1e-21 m); 1e-3 m does not.
    """
    for gap, ok in ((1e-17, True), (1e-3, False)):
        b = MechanismBuilder("centred")
        for name, theta in (("A", 0.0), ("B", 2.1), ("C", 4.2)):
            limb = b.limb(name)
            for label, axis in (("r1", polar(1.0, theta, -0.6)), ("r2", polar(1.0, theta + 0.6)), ("r3", Z)):
                limb.revolute(label, at=[0, 0, 0], axis=axis)
            limb.tip(at=[gap if name == "C" else 0.0, 0, 0])
        if ok:
            assert pin.buildModelFromXML(b.urdf()).njoints == 10
        else:
            with pytest.raises(ConfigurationError, match="limb 'C' tip is 0.001 m"):
                b.urdf()


def test_robot_name_is_escaped():
    b = one_limb('R&D "arm" <2>')
    b.limbs[0].tip(at=[0, 0, 0])
    model = pin.buildModelFromXML(b.urdf())
    assert model.name == 'R&D_"arm"_<2>'


#: text a TOML basic string must escape or may hold as it is: non-ASCII letters and digits, quotes, backslashes,
#: tab, every other control character U+0000-U+001F, DEL
AWKWARD = 'café x² "quoted" back\\slash tab\there ' + "".join(map(chr, range(0x20))) + "\x7f end"
#: configuration names that are no bare TOML key (bare: ASCII letters, digits, _ and -), and one that is
#: (printable all: the loader refuses control characters in names)
AWKWARD_NAMES = ["é", "x²", "Ωmega", 'say "hi"', "back\\slash", "two words", "a.b", "ok-name_1"]


def test_names_and_descriptions_round_trip_through_tomllib(tmp_path):
    """The written file parses with tomllib (independent of pinmob's writer) to the builder's values, and loads."""
    b = MechanismBuilder("two", AWKWARD)
    for name, y in (("A", 0.1), ("B", -0.1)):
        limb = b.limb(name)
        limb.revolute("r", at=[0, y, 0], axis=[1, 0, 0])
        limb.tip(at=[0, 0, 0])
    path = b.write(tmp_path, "two", {name: {"joints": {"A_r": 0.0}} for name in AWKWARD_NAMES})
    text = path.read_text(encoding="utf-8")
    doc = tomllib.loads(text)
    assert doc["description"] == AWKWARD and list(doc["configurations"]) == AWKWARD_NAMES
    assert all(doc["configurations"][name] == {"joints": {"A_r": 0.0}} for name in AWKWARD_NAMES)
    assert "[configurations.ok-name_1]" in text  # a bare key stays bare (the built-in models' files)
    mech = pinmob.load(path)
    assert mech.description == AWKWARD and list(mech.configurations) == AWKWARD_NAMES


@settings(max_examples=300, deadline=None)
@given(
    key=st.one_of(st.text(st.characters(max_codepoint=0x7F)), st.text()),
    text=st.one_of(st.text(st.characters(max_codepoint=0x7F)), st.text()),
)
def test_any_key_and_string_round_trip_through_tomllib(key, text):
    """Any key and string (ASCII with its control characters, or any Unicode but lone surrogates) read back equal."""
    assert tomllib.loads(f"v = {toml_value({key: [text]})}") == {"v": {key: [text]}}


#: a lone surrogate: a Python str holds it, UTF-8 cannot (Python's own codec refuses it, checked below)
LONE = "joint\ud800x"


def _two_limbs(name="two", description=""):
    b = MechanismBuilder(name, description)
    for limb_name, y in (("A", 0.1), ("B", -0.1)):
        limb = b.limb(limb_name)
        limb.revolute("r", at=[0, y, 0], axis=[1, 0, 0])
        limb.tip(at=[0, 0, 0])
    return b


def test_a_lone_surrogate_is_refused_by_name_before_anything_is_written(tmp_path):
    """A mechanism name, description or configuration name holding a lone surrogate: one ConfigurationError naming
    the text and the surrogate (before: a raw UnicodeEncodeError when the file was written, or none at the
    constructor), and no file written. Text on either side of the surrogates (U+D7FF, U+E000) still reads back."""
    with pytest.raises(UnicodeEncodeError):
        LONE.encode("utf-8")  # the truth: no UTF-8 file can hold it
    with pytest.raises(ConfigurationError, match=r"mechanism name 'joint\\ud800x' holds the lone surrogate"):
        MechanismBuilder(LONE)
    with pytest.raises(ConfigurationError, match=r"description 'joint\\ud800x' holds the lone surrogate"):
        MechanismBuilder("two", LONE)
    b = _two_limbs()
    with pytest.raises(ConfigurationError, match=r"configuration name 'joint\\ud800x' holds the lone surrogate"):
        b.write(tmp_path, "two", {LONE: {"joints": {"A_r": 0.0}}})
    with pytest.raises(ConfigurationError, match=r"'joint\\ud800x' holds the lone surrogate '\\ud800' \(character 6\)"):
        b.write(tmp_path, "two", {"home": {"joints": {LONE: 0.0}}})  # a key in a configuration's table
    assert list(tmp_path.iterdir()) == []
    edges = "\ud7ff \ue000"
    path = _two_limbs(edges, edges).write(tmp_path, "two", {edges: {"joints": {"A_r": 0.0}}})
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    assert doc["name"] == doc["description"] == edges and list(doc["configurations"]) == [edges]


_WRITE_IN_ASCII_LOCALE = """
import locale, sys, tomllib
from pathlib import Path
from pinmob.builder import MechanismBuilder
assert locale.getpreferredencoding(False) != "UTF-8"  # the locale's encoding is ASCII here
b = MechanismBuilder("two", "caf\\u00e9")
for name, y in (("A", 0.1), ("B", -0.1)):
    limb = b.limb(name)
    limb.revolute("r", at=[0, y, 0], axis=[1, 0, 0])
    limb.tip(at=[0, 0, 0])
path = b.write(Path(sys.argv[1]), "two", {"\\u00e9": {"joints": {"A_r": 0.0}}})
doc = tomllib.loads(path.read_bytes().decode("utf-8"))
print(ascii(doc["description"]), ascii(list(doc["configurations"])))
"""


def test_the_builder_writes_utf8_whatever_the_locale(tmp_path):
    """In an ASCII locale (C, without Python's UTF-8 mode or locale coercion) a description and a configuration
    name with é are written as UTF-8, which tomllib reads back (before: a raw UnicodeEncodeError, 'ascii' codec)."""
    env = dict(os.environ, LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    out = subprocess.run(
        [sys.executable, "-c", _WRITE_IN_ASCII_LOCALE, str(tmp_path)], env=env, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["'caf\\xe9'", "['\\xe9']"]


def test_toml_string_and_key_refuse_a_lone_surrogate():
    """pinmob.io.toml_string and toml_key (the builder's and pinmob fix's writers): a ConfigurationError, not a str
    that fails when written; each surrogate U+D800..U+DFFF alike, its neighbours written as tomllib reads them."""
    for code in (0xD800, 0xDBFF, 0xDC00, 0xDFFF):
        for write in (pinmob.io.toml_string, pinmob.io.toml_key):
            with pytest.raises(ConfigurationError, match="lone surrogate"):
                write(f"a{chr(code)}")
    for code in (0xD7FF, 0xE000):
        text = f"a{chr(code)}"
        assert tomllib.loads(f"{pinmob.io.toml_key(text)} = {pinmob.io.toml_string(text)}") == {text: text}


def test_write_refuses_unclosed_configurations_and_foreign_files(tmp_path):
    """Nothing is written when a configuration does not close; a file the builder did not write is not replaced."""
    b = MechanismBuilder("two")
    for name, y in (("A", 0.1), ("B", -0.1)):
        limb = b.limb(name)
        limb.revolute("r", at=[0, y, 0], axis=[1, 0, 0])
        limb.tip(at=[0, 0, 0])
    with pytest.raises(ConfigurationError, match="configuration .bad. of .two. does not close"):
        b.write(tmp_path, "two", {"bad": {"joints": {"A_r": 0.3}}})
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "two.urdf").write_text("<robot name='mine'/>\n")
    with pytest.raises(ConfigurationError, match="was not written by pinmob.builder: not overwritten"):
        b.write(tmp_path, "two", {"home": {"joints": {}}})
    assert (tmp_path / "two.urdf").read_text() == "<robot name='mine'/>\n"
    (tmp_path / "two.urdf").unlink()
    b.write(tmp_path, "two", {"home": {"joints": {}}})
    b.write(tmp_path, "two", {"home": {"joints": {}}})  # its own output is replaced


def test_round_off_is_written_as_zero():
    """Reproducible files: components below 1e-12 x max(1, largest) are written as 0, whatever their sign."""
    assert vector([-6.73e-18, -0.12, 0.0]) == vector([8.01e-18, -0.12, -0.0]) == "0 -0.12 0"
    assert vector([3e-13, 2.0]) == "0 2"
    assert vector([3e-12, 0.5]) == "3e-12 0.5"
    assert toml_value(-1e-17) == "0.0" and toml_value(0.25) == "0.25" and toml_value(2.0) == "2.0"
    assert vector([2e12, 1.5, -1.9]) == "2000000000000 0 0" and vector([]) == "" and cleaned([]).size == 0
    with pytest.raises(ConfigurationError, match=r"cannot write \[1.0, nan\]"):
        vector([1.0, np.nan])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_subnormal=False) | st.sampled_from([0.0, -0.0, 1e-13, -4e-13]), max_size=9))
def test_round_off_zeroing_as_array_arithmetic(xs):
    """The zeroing, done in Python floats, is that of the array formula of the docstring, to the last bit."""
    a = np.array(xs, float)
    expected = np.where(np.abs(a) <= ZERO_RTOL * max(1.0, float(np.abs(a).max(initial=0.0))), 0.0, a)
    assert cleaned(xs).tobytes() == expected.tobytes()


def test_angles_are_written_in_one_range():
    """Reproducible files: a revolute angle is written in (-pi, pi] whatever multiple of 2 pi it came with (the
    Delta's rods-horizontal values came out 2 pi apart on two machines); a joint whose limits exclude that value
    keeps the representative inside them closest to 0; prismatic values and joint-space directions (approach)
    are not angles and stay; a half turn is roll pi in a URDF whatever the sign of its zero entries' round-off."""
    b = MechanismBuilder("wrap")
    limb = b.limb("A")
    limb.revolute("r", at=[0, 0.1, 0], axis=Z)
    limb.revolute("wide", at=[0, 0.2, 0], axis=Z, lower=0.0, upper=2 * np.pi)
    limb.continuous("c", at=[0, 0.3, 0], axis=Z)
    limb.prismatic("p", at=[0, 0.3, 0], axis=[1, 0, 0], lower=-10, upper=10)
    limb.tip(at=[0, 0.3, 0])
    text = b.toml(
        "wrap.urdf",
        {
            "one": {"joints": {"A_r": 7.0, "A_wide": -1.0, "A_c": -np.pi, "A_p": 7.0}},
            "two": {"seed": {"A_r": -4.0}, "approach": {"A_r": 7.0}},
        },
    )
    doc = tomllib.loads(text)
    joints = doc["configurations"]["one"]["joints"]
    assert_allclose(
        [joints["A_r"], joints["A_wide"], joints["A_c"], joints["A_p"]],
        [7 - 2 * np.pi, 2 * np.pi - 1, np.pi, 7.0],
        atol=1e-14,
    )
    assert_allclose(doc["configurations"]["two"]["seed"]["A_r"], 2 * np.pi - 4, atol=1e-14)
    assert doc["configurations"]["two"]["approach"] == {"A_r": 7.0}
    half_turn = np.diag([1.0, -1.0, -1.0])
    for eps in (1e-17, -1e-17, 1e-13, -1e-13, 0.0, -0.0):
        r = half_turn.copy()
        r[2, 1], r[1, 2] = eps, -eps
        assert rpy(r)[0] == np.pi, eps
