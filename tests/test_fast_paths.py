"""Each faster computation against the straightforward one it replaces, on random matrices and the built-in models."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import scipy.linalg
from numpy.testing import assert_allclose

import pinmob
from pinmob.screw.rank import singular_values, svd
from pinmob.screw.screw_groups import _generalised_eigh


@pytest.mark.parametrize("shape", [(5, 6), (6, 6), (6, 3), (18, 15), (30, 36), (4, 5, 6)])
def test_svd_is_numpys(shape):
    """rank.svd calls the LAPACK gufunc behind np.linalg.svd: bit for bit the same, one matrix or a stack."""
    a = np.random.default_rng(3).normal(size=shape)
    for full in (True, False):
        for mine, ref in zip(svd(a, full_matrices=full), np.linalg.svd(a, full_matrices=full)):
            assert np.array_equal(mine, ref)
    assert np.array_equal(singular_values(a), np.linalg.svd(a, compute_uv=False))


def test_svd_of_a_stack_is_the_svd_of_each():
    a = np.random.default_rng(4).normal(size=(7, 5, 6))
    stacked = svd(a)
    for i in range(a.shape[0]):
        for s, one in zip(stacked, svd(a[i])):
            assert np.array_equal(s[i], one)


def test_svd_of_a_matrix_with_nan_raises():
    with pytest.raises(np.linalg.LinAlgError), np.errstate(invalid="ignore"):
        svd(np.full((3, 3), np.nan))


@pytest.mark.parametrize("size", [1, 2, 3])
def test_generalised_eigh_is_scipys(size):
    """The Cholesky reduction gives SciPy's eigenvalues and, up to sign, its B-orthonormal eigenvectors."""
    rng = np.random.default_rng(size)
    for _ in range(20):
        m = rng.normal(size=(size, size))
        a = m + m.T
        g = rng.normal(size=(size, size))
        b = g @ g.T + 0.1 * np.eye(size)
        vals, vecs = _generalised_eigh(a, b)
        ref_vals, ref_vecs = scipy.linalg.eigh(a, b)
        assert_allclose(vals, ref_vals, rtol=1e-10, atol=1e-12)
        assert_allclose(vecs.T @ b @ vecs, np.eye(size), atol=1e-10)
        assert_allclose(np.abs(vecs.T @ b @ ref_vecs), np.eye(size), atol=1e-8)  # distinct eigenvalues


HEAVY = ("numba", "scipy", "yaml", "matplotlib", "meshcat", "mujoco", "dask")


def test_import_pinmob_loads_no_optional_package():
    """``import pinmob`` (and a whole analysis, as ``pinmob analyze`` runs it) loads none of the heavy packages."""
    import subprocess
    import sys

    code = (
        "import sys, pinmob\n"
        f"heavy = {HEAVY!r}\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
        "r = pinmob.analyze(pinmob.load('3-PUU'), 'generic'); r.to_dict(); str(r)\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]", out[0]
    assert out[1] == "[]", out[1]


def test_a_scan_loads_the_viewer_only_to_draw(tmp_path):
    """``pinmob scan`` without ``--show`` or ``--html`` does not import the viewer (20 ms of a fresh process); with
    ``--html`` it does, and writes the page."""
    import subprocess
    import sys

    page = tmp_path / "scan.html"
    code = (
        "import contextlib, io, sys\n"
        "from pinmob.cli import main\n"
        "grid = ['scan', '3-PUU', '--grid', 'x:-0.01:0.01:2', 'y:-0.01:0.01:2', '--at', 'generic', '--no-progress']\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    status = main(grid)\n"
        "print(status, 'pinmob.viewer' in sys.modules)\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    status = main(grid + ['--html', {str(page)!r}])\n"
        "print(status, 'pinmob.viewer' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[:2] == ["0 False", "0 True"], out
    assert page.read_text(encoding="utf-8").lstrip().lower().startswith("<!doctype html")


def test_the_finite_analysis_loads_when_asked_for():
    """Its modules (branches, tangent cone, path follower, ...) are not part of ``import pinmob`` nor of an analysis
    without ``finite=True``; with it they load and the report has the finite part."""
    import subprocess
    import sys

    code = (
        "import sys, pinmob\n"
        "finite = ('pinmob.analysis.finite.finite_mobility', 'pinmob.analysis.finite.tangent_cone', 'pinmob.analysis.follow.motion_path')\n"
        "print(sorted(m for m in finite if m in sys.modules))\n"
        "mech = pinmob.load('3-PUU')\n"
        "pinmob.analyze(mech, 'generic').to_dict()\n"
        "print(sorted(m for m in finite if m in sys.modules))\n"
        "print(pinmob.analyze(mech, 'generic', finite=True).to_dict()['finite_dof'])\n"
        "print(sorted(m for m in finite if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[:2] == ["[]", "[]"]
    assert out[2] == "3"  # the 3-PUU's generic configuration is regular: finite = instantaneous = 3 (3T)
    assert out[3] == str(
        [
            "pinmob.analysis.finite.finite_mobility",
            "pinmob.analysis.finite.tangent_cone",
            "pinmob.analysis.follow.motion_path",
        ]
    )


def closed_configurations() -> list[tuple[str, object]]:
    """(label, Configuration) of every built-in model's named configurations and of the 11 Extended URDF robots."""
    import warnings
    from pathlib import Path

    import pinmob
    from pinmob.assembly.relaxation import find_closed_relaxed

    out = []
    for name in pinmob.builtin_models():
        mech = pinmob.load(name)
        out += [(f"{name}/{c}", pinmob.Configuration(mech, c)) for c in mech.configurations]
    folder = Path(__file__).resolve().parent / "data" / "example-parallel-robots"
    for robot in sorted(p.name for p in folder.iterdir() if (p / "robot.yaml").exists()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # their meshes are not included
            mech, found, _ = find_closed_relaxed(pinmob.load(folder / robot / "robot.yaml"), restarts=3)
        out.append((robot, pinmob.Configuration(mech, found.q)))
    return out


@pytest.fixture(scope="module")
def configurations() -> list[tuple[str, object]]:
    return closed_configurations()


def test_closure_ranks_from_the_left_null_space(configurations):
    """Per-closure redundancy from one SVD of K (its left null space) equals the SVDs of K without each closure.

    At the default tolerance the one-SVD path decides every case; at loose tolerances, where a soft
    dependency sits near the threshold, it declines (and the SVDs per closure decide).
    """
    from pinmob.analysis.chain.closed_chain import closed_chain
    from pinmob.analysis.chain.redundancy import closure_ranks, closure_ranks_by_removal, implied_rows
    from pinmob.screw.rank import RTOL

    redundant, declined = 0, 0
    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        for rtol in (RTOL, 1e-9, 1e-7, 1e-5, 1e-4, 1e-3, 1e-2):
            chain = closed_chain(conf, rtol)  # type: ignore[arg-type]
            s = chain.decision.singular_values
            ref = float(s[0]) if s.size else 0.0
            straight = closure_ranks_by_removal(mech, chain.k_hat, rtol, ref)
            assert closure_ranks(mech, chain.k_hat, rtol, ref, chain.left_null, chain.decision.margin) == straight
            implied = implied_rows(mech, chain.left_null, rtol, chain.decision.margin)
            if implied is None:
                assert rtol != RTOL, label
                declined += 1
                continue
            assert implied == [c.rows - c.essential for c in straight], (label, rtol)
            redundant += sum(implied)
    assert redundant > 0  # the cases include closures with equations implied by the others
    assert declined < 30


def test_output_rows_are_pinocchios_joint_jacobians(configurations):
    """The joint centres' rows, all at once from the world Jacobian, are Pinocchio's joint Jacobians.

    Against the computation they replace: ``pin.getJointJacobian(..., LOCAL_WORLD_ALIGNED)[:3] * col / L``
    per joint, referred to the joint's centre (:mod:`pinmob.analysis.chain.joint_centres`: its frame origin but for
    the revolutes of a ball or universal joint drawn elsewhere on their axes), with the same exact zeros (the
    columns of the joints that do not support it); the other entries to round-off.
    """
    import pinocchio as pin

    from pinmob.analysis.chain.closed_chain import closed_chain_columns, frame_rows, output_rows, supported_columns
    from pinmob.analysis.chain.joint_centres import joint_centres

    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        model, data, length = mech.model, conf.data, mech.length_scale  # type: ignore[attr-defined]
        col = closed_chain_columns(conf)  # type: ignore[arg-type]
        frames = [mech.platform] if mech.has_platform else []
        rows = [frame_rows(conf, f) for f in frames]  # type: ignore[arg-type]
        centres = joint_centres(conf)  # type: ignore[arg-type]
        for j in range(1, model.njoints):
            jac = np.reshape(pin.getJointJacobian(model, data, j, pin.LOCAL_WORLD_ALIGNED), (6, model.nv))
            r = centres[j - 1] - data.oMi[j].translation  # the centre on joint j's axis, from its frame origin
            rows.append((jac[:3] - pin.skew(r) @ jac[3:]) * col / length)  # v + w x r
        rows += [
            conf.frame_jacobian(c.frame_a_id)[:3] * col / length  # type: ignore[attr-defined]
            for c in mech.all_closures
            if c.type not in ("6d", "joint")
        ]
        ref = np.vstack(rows)
        mine = output_rows(conf, frames)  # type: ignore[arg-type]
        assert mine.shape == ref.shape, label
        block = slice(6 * len(frames), 6 * len(frames) + 3 * (model.njoints - 1))  # the joint centres' rows
        absent = ~np.repeat(supported_columns(mech), 3, axis=0)  # type: ignore[arg-type]
        assert np.all(mine[block][absent] == 0) and np.all(ref[block][absent] == 0), label
        others = np.ones(len(ref), dtype=bool)
        others[block] = False
        assert np.array_equal(mine[others] == 0, ref[others] == 0), label  # frames and closure points
        assert_allclose(mine, ref, rtol=1e-14, atol=1e-14, err_msg=label)


def test_rates_of_is_the_selector_product(configurations):
    """The held joints' rates picked as rows of the closed chain's motions: the numbers of the selector matrix's product."""
    from pinmob.analysis.chain.actuation import held_indices
    from pinmob.analysis.chain.closed_chain import closed_chain, rates_of
    from pinmob.screw.rank import RTOL

    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        null = closed_chain(conf, RTOL).null  # type: ignore[arg-type]
        idx = held_indices(mech, mech.actuated)
        selector = np.zeros((idx.size, mech.model.nv))
        selector[np.arange(idx.size), idx] = 1.0
        product = selector @ null
        mine = rates_of(null, idx)
        assert mine.shape == product.shape and np.array_equal(mine, product), label


def test_canonical_directions_closed_form_is_the_greedy():
    """The closed forms per dimension give the greedy's basis: random subspaces, axis-aligned ones and ties."""
    from pinmob.screw.bases import canonical_directions, canonical_directions_greedy

    rng = np.random.default_rng(5)
    cases = [np.eye(3)[:, :k] for k in range(4)]
    cases += [np.array([[1.0, 1.0], [1.0, -1.0], [0.0, 0.0]]), np.array([[1.0], [1.0], [0.0]]), np.ones((3, 1))]
    for _ in range(2000):
        r = int(rng.integers(1, 4))
        m = rng.normal(size=(3, r)) @ rng.normal(size=(r, int(rng.integers(1, 4))))
        cases.append(np.round(m) if rng.random() < 0.3 else m)
    for m in cases:
        fast, greedy = canonical_directions(m), canonical_directions_greedy(m)
        assert fast.shape == greedy.shape
        assert_allclose(fast, greedy, atol=1e-12)


def test_principal_screws_of_the_whole_space():
    """The whole space in closed form (3 free vectors, 3 lines through the origin) is what the steps find."""
    from pinmob.screw.classify import principal_screws, principal_screws_of_span

    rng = np.random.default_rng(6)
    for _ in range(100):
        basis = rng.normal(size=(6, 6)) * rng.uniform(0.01, 100.0, 6)
        q = np.linalg.qr(basis)[0]
        trans, screws = principal_screws(basis[:3], basis[3:])
        ref_trans, ref_screws = principal_screws_of_span(q)
        assert_allclose(trans, ref_trans, atol=1e-12)
        assert len(screws) == len(ref_screws) == 3
        for (u, p, h), (ru, rp, rh) in zip(screws, ref_screws):
            assert_allclose(u, ru, atol=1e-12)
            assert_allclose(p, rp, atol=1e-12)
            assert h == rh == 0.0


def test_builtin_names_read_from_their_name_line(tmp_path):
    """The built-in names from each file's name line are the parsed files' names; other files are parsed."""
    import tomllib

    from pinmob.io.builtin import builtin_dir, builtin_models, model_name

    parsed = {}
    for path in sorted(builtin_dir().glob("*.toml")):
        with path.open("rb") as fh:
            parsed[str(tomllib.load(fh).get("name", path.stem))] = path
    assert builtin_models() == parsed
    odd = {
        "a.toml": 'description = """\nname = "not this"\n"""\nname = "this"\n',
        "b.toml": "name = 'literal'\n",
        "c.toml": '[limbs]\nname = "a limb"\n',
        "d.toml": 'name = "with \\"quotes\\""\n',
    }
    for file, text in odd.items():
        (tmp_path / file).write_text(text)
        assert model_name(tmp_path / file) == str(tomllib.loads(text).get("name", Path(file).stem))


def test_builtin_names_are_read_again_when_a_file_changes(tmp_path):
    """The names are cached per file name, size and modification time: a changed or new file is read again."""
    import os

    from pinmob.io.builtin import models_in

    first = tmp_path / "a.toml"
    first.write_text('name = "one"\n')
    (tmp_path / "notes.txt").write_text('name = "no model"\n')
    assert models_in(tmp_path) == {"one": first}
    first.write_text('name = "three"\n')  # another size
    assert models_in(tmp_path) == {"three": first}
    stat = first.stat()
    first.write_text('name = "seven"\n')  # the same size, a later time (set: the clock may not have moved)
    os.utime(first, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1))
    assert models_in(tmp_path) == {"seven": first}
    second = tmp_path / "0.toml"
    second.write_text('name = "zero"\n')
    assert list(models_in(tmp_path).items()) == [("zero", second), ("seven", first)]
    assert models_in(tmp_path / "absent") == {}


def test_joint_masks_are_each_joints_own_columns():
    """linear_velocity_mask and angle_mask (one norm over all columns) from each joint's own motion subspace."""
    from pinmob.model import angle_mask, linear_velocity_mask

    for name in pinmob.builtin_models():
        model = pinmob.load(name).model
        linear, angle = np.zeros(model.nv, bool), np.zeros(model.nq, bool)
        q = pin.neutral(model)
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if not joint.nv:
                continue
            data = joint.createData()
            joint.calc(data, q)
            s = np.asarray(data.S).reshape(6, -1)
            linear[joint.idx_v : joint.idx_v + joint.nv] = np.linalg.norm(s[3:], axis=0) < 1e-12
            if joint.nq == joint.nv:
                angle[joint.idx_q : joint.idx_q + joint.nq] = (np.linalg.norm(s[:3], axis=0) < 1e-12) & (
                    np.linalg.norm(s[3:], axis=0) > 0
                )
        assert np.array_equal(linear_velocity_mask(model), linear), name
        assert np.array_equal(angle_mask(model), angle), name


def test_printable_fast_path_is_the_category_test():
    """printable() (str.isprintable first) refuses exactly the names with a Cc or Cf character."""
    import sys
    import unicodedata

    from pinmob.model.names import printable

    for c in map(chr, range(sys.maxunicode + 1)):
        ref = unicodedata.category(c) not in ("Cc", "Cf")
        assert printable(c) == ref and printable(f"a{c}b") == ref, hex(ord(c))


def test_loading_a_builtin_model_loads_no_other_reader():
    """``import pinmob`` and loading a built-in model (TOML + URDF) leave the other formats' readers unloaded;
    their names in pinmob.io load them when read."""
    import subprocess
    import sys

    readers = ("pinmob.io.extended_urdf", "pinmob.io.mjcf", "pinmob.io.xacro_file", "pinmob.io.fixed_files")
    code = (
        "import sys, pinmob\n"
        f"readers = {readers!r}\n"
        "pinmob.load('3-PUU')\n"
        "print(sorted(m for m in readers if m in sys.modules))\n"
        "import pinmob.io\n"
        "[getattr(pinmob.io, n) for n in pinmob.io.__all__]\n"
        "print(sorted(m for m in readers if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]", out[0]
    assert out[1] == str(sorted(readers)), out[1]


def test_meshes_are_loaded_only_when_drawn():
    """Loading and analysing the 3-UR5 (what pinmob analyze does) loads no mesh; its visual model does, once."""
    import pickle

    import pinmob

    mech = pinmob.load("3-UR5")
    assert mech.geometry is not None and not mech.geometry.loaded
    report = pinmob.analyze(mech, "generic")
    report.to_dict()
    str(report)
    assert not mech.geometry.loaded
    copy = pickle.loads(pickle.dumps(mech))
    visual = mech.visual_model
    assert mech.geometry.loaded and visual is not None and visual.ngeoms == 21
    assert mech.visual_model is visual  # loaded once
    assert copy.geometry is not None and not copy.geometry.loaded  # a copy loads its own when it draws
    assert copy.visual_model is not None and copy.visual_model.ngeoms == 21


def test_rank_rule_rows_is_the_rank_rule():
    from pinmob.screw.rank import rank_rule, rank_rule_rows

    rng = np.random.default_rng(8)
    s = -np.sort(-np.abs(rng.normal(size=(300, 6))) * 10.0 ** rng.integers(-12, 2, size=(300, 6)), axis=1)
    s[:5] = 0.0
    for rtol in (1e-6, 1e-3, 1e-9):
        assert list(rank_rule_rows(s, rtol)) == [rank_rule(row, rtol)[0] for row in s]


def _batch_cases():
    import pinocchio as pin

    import pinmob

    rng = np.random.default_rng(9)
    for name in pinmob.builtin_models():
        mech = pinmob.load(name)
        if not mech.has_platform or not mech.limbs or mech.coupling_closures or any(b.closures for b in mech.limbs):
            continue
        qs = [pinmob.closed_configuration(mech, c) for c in mech.configurations]
        for _ in range(3):  # nearby closed configurations: generic, where the named ones are special
            try:
                qs.append(
                    pinmob.project(mech, pin.integrate(mech.model, qs[0], rng.normal(0.0, 0.02, mech.model.nv))).q
                )
            except pinmob.ClosureError:
                break
        yield name, mech, np.array(qs)


def test_batch_numpy_engine_is_the_single_analysis_bit_for_bit():
    """The numpy engine makes the single analyses' SVDs, batched: the same ranks and singular values, bit for bit."""
    import pinmob
    from pinmob.analysis.batch.batch_analysis import analyze_batch

    for name, mech, qs in _batch_cases():
        batch = analyze_batch(mech, qs, singular_values=True, engine="numpy")
        for i, q in enumerate(qs):
            report = pinmob.analyze(mech, q)
            sing = pinmob.analyze_singularity(report.state)
            assert batch.dof[i] == report.dof and batch.locked_dof[i] == sing.locked_dof, name
            assert list(batch.limb_twist_rank[i]) == [limb.twist_rank for limb in report.limbs]
            assert np.array_equal(batch.singular_values[i], report.singular_values), name
            assert np.array_equal(batch.actuation_singular_values[i], np.nan_to_num(sing.actuation_singular_values))
            assert np.array_equal(batch.limb_ratio[i], [sing.distances[f"limb {b.name}"] for b in mech.limbs])


def test_batch_engines_agree():
    """numba's compiled loop (one-sided Jacobi SVDs) and the numpy engine (LAPACK): same ranks, values to round-off."""
    pytest.importorskip("numba")
    from pinmob.analysis.batch.batch_analysis import analyze_batch

    checked = 0
    for name, mech, qs in _batch_cases():
        fast = analyze_batch(mech, qs, singular_values=True, engine="numba")
        ref = analyze_batch(mech, qs, singular_values=True, engine="numpy")
        assert (fast.engine, ref.engine) == ("numba", "numpy")
        for field in ("dof", "constraint_rank", "limb_twist_rank", "locked_dof"):
            assert np.array_equal(getattr(fast, field), getattr(ref, field)), (name, field)
        for field in ("singular_values", "actuation_singular_values", "limb_ratio"):
            assert_allclose(getattr(fast, field), getattr(ref, field), atol=1e-12, err_msg=f"{name} {field}")
        checked += len(qs)
    assert checked > 20


def test_jacobi_svd_is_lapacks():
    """The compiled loop's one-sided Jacobi SVD (span): LAPACK's singular values, the rank, a null space orthogonal to
    the rows, and the rotated matrix ``a V = U diag(sv)``, its columns sorted with the values."""
    pytest.importorskip("numba")
    from pinmob.screw.jacobi import span

    rng = np.random.default_rng(10)
    for _ in range(300):
        rows, rank = int(rng.integers(1, 19)), int(rng.integers(0, 7))
        a = rng.normal(size=(rows, rank)) @ rng.normal(size=(rank, 6)) if rank else np.zeros((rows, 6))
        a *= 10.0 ** rng.uniform(-3, 3)
        g, sv, v = np.zeros((18, 6)), np.zeros(6), np.zeros((6, 6))
        g[:rows] = a
        rank = span(g, rows, 1e-9, sv, v)
        ref = np.zeros(6)
        ref[: min(rows, 6)] = np.linalg.svd(a, compute_uv=False)
        scale = max(1.0, float(ref[0]))
        assert_allclose(sv, ref, atol=1e-13 * scale)
        assert_allclose(v.T @ v, np.eye(6), atol=1e-13)
        true_rank = int(np.sum(ref > 1e-10 * scale))
        assert rank == true_rank
        assert np.abs(a @ v[:, true_rank:]).max(initial=0.0) <= 1e-12 * scale
        assert_allclose(g[:rows], a @ v, atol=1e-12 * scale)
        assert_allclose(np.linalg.norm(g[:rows], axis=0), sv, atol=1e-13 * scale)


def test_batch_without_numba():
    """Without numba (an optional extra) the batch path runs on numpy; asking for numba says how to install it."""
    import subprocess
    import sys

    code = (
        "import sys; sys.modules['numba'] = None\n"
        "import pinmob\n"
        "from pinmob.analysis.batch.batch_analysis import analyze_batch\n"
        "mech = pinmob.load('3-PUU'); q = pinmob.closed_configuration(mech, 'generic')\n"
        "r = analyze_batch(mech, q[None, :])\n"
        "print(r.engine, int(r.dof[0]))\n"
        "try:\n"
        "    analyze_batch(mech, q[None, :], engine='numba')\n"
        "except pinmob.ConfigurationError as exc:\n"
        "    print(exc)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.splitlines()
    assert out[0] == "numpy 3"
    assert "pinmob[fast]" in out[1]


def test_free_vectors_only_shortcut():
    """A system without direction parts (|w| <= rtol) is all free vectors: the shortcut skips the SVD of w, and
    the canonical directions do not depend on the basis it would have given (any orthonormal one)."""
    from pinmob.screw.bases import canonical_directions
    from pinmob.screw.classify import principal_screws

    rng = np.random.default_rng(11)
    for k in (1, 2, 3):
        for _ in range(50):
            v = np.linalg.qr(rng.normal(size=(3, 3)))[0][:, :k]
            w = rng.normal(size=(3, k)) * 1e-9
            trans, screws = principal_screws(v, w)
            basis = np.linalg.qr(rng.normal(size=(k, k)))[0]
            assert screws == []
            assert_allclose(trans, canonical_directions(v @ basis), atol=1e-12)


def test_every_array_of_a_report_is_read_only():
    """The arrays found by their annotations are every array the results hold (walked through a whole report)."""
    import dataclasses

    import pinmob

    seen = 0

    def walk(value: object) -> None:
        nonlocal seen
        if isinstance(value, np.ndarray):
            assert not value.flags.writeable
            seen += 1
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            for f in dataclasses.fields(value):
                walk(getattr(value, f.name))
        elif isinstance(value, (tuple, list)):
            for v in value:
                walk(v)
        elif isinstance(value, dict):
            for v in value.values():
                walk(v)

    for name in ("3-PUU-flat", "6-UPS", "Delta"):
        mech = pinmob.load(name)
        report = pinmob.analyze(mech, next(iter(mech.configurations)), paper=True)
        walk([report.mobility, report.mechanism_mobility, report.singularity, report.paper])
    assert seen > 50


def test_joint_rates_are_ordered_by_their_printed_magnitude_then_model_order():
    """Rates by name, largest first as printed (three significant digits), ties in the model's joint order:
    0.0124 before 0.0121 (a sort to three decimals took them as equal), and the five-bar's two elbows, equal by
    symmetry to round-off, always in model order."""
    from pinmob.analysis.chain.joint_rates import joint_rates

    mech = pinmob.load("3-PUU")
    names = [mech.model.names[j] for j in range(1, mech.model.njoints)]
    dq = np.zeros(mech.model.nv)
    index = {n: mech.model.joints[mech.model.getJointId(n)].idx_v for n in names}
    dq[index[names[0]]], dq[index[names[1]]], dq[index[names[2]]] = 0.0121, 0.0124, -1.0
    assert list(joint_rates(mech, dq).items()) == [(names[2], -1.0), (names[1], 0.0124), (names[0], 0.0121)]
    dq[:] = 0.0
    dq[index[names[0]]], dq[index[names[1]]] = 1.0 - 3e-7, -1.0  # equal to the printed digits: model order
    assert list(joint_rates(mech, dq)) == [names[0], names[1]]


def test_a_multi_degree_joint_prints_the_first_of_its_equal_largest_components():
    """A free joint (MuJoCo's connect.xml) whose two largest components are equal but for round-off prints the
    first, whichever is larger by 1e-12 (it printed joint1 +1 or -1 as round-off had it)."""
    from pinmob.analysis.chain.joint_rates import joint_rates

    mech = pinmob.load(Path(__file__).parent / "data" / "third_party" / "mujoco_testdata" / "connect.xml")
    joint = mech.model.joints[1]
    assert joint.nv == 6
    for eps in (1e-12, -1e-12):
        dq = np.zeros(mech.model.nv)
        dq[joint.idx_v + 3], dq[joint.idx_v + 4] = -0.6094494, 0.6094494 + eps
        assert joint_rates(mech, dq) == {mech.model.names[1]: -1.0}


def test_named_pose_is_assembled_once_per_mechanism_and_given_as_a_copy():
    """A named platform pose is kept per mechanism: the same vector as a fresh mechanism assembles, never shared."""
    mech = pinmob.load("6-UPS")
    first = pinmob.closed_configuration(mech, "generic")
    first[:] = 0.0  # the caller's copy; the kept vector is untouched
    again = pinmob.closed_configuration(mech, "generic")
    fresh = pinmob.closed_configuration(pinmob.load("6-UPS"), "generic")
    assert np.array_equal(again, fresh)
    assert again is not pinmob.closed_configuration(mech, "generic")
    assert np.array_equal(pinmob.analyze(mech, "generic").state.q, fresh)
    with pytest.raises(pinmob.ClosureError):  # a tighter tolerance is its own entry, assembled and checked
        pinmob.closed_configuration(mech, "generic", 1e-300)


def test_closure_ranks_of_a_full_row_rank_k_need_no_svd(configurations):
    """K of full row rank (clear margin): each closure's rows have full rank and every closure is essential,
    as the SVDs per closure find; each block's singular values are at least K's smallest."""
    from pinmob.analysis.chain.closed_chain import closed_chain
    from pinmob.analysis.chain.redundancy import CLEAR, closure_ranks, closure_ranks_by_removal
    from pinmob.screw.rank import singular_values

    shortcut = 0
    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        for rtol in (1e-9, 1e-6, 1e-3):
            chain = closed_chain(conf, rtol)  # type: ignore[arg-type]
            dec = chain.decision
            if chain.left_null.shape[1] or dec.margin < CLEAR or not chain.k_hat.size:
                continue
            shortcut += 1
            ref = float(dec.singular_values[0])
            assert closure_ranks(mech, chain.k_hat, rtol, ref, chain.left_null, dec.margin) == (
                closure_ranks_by_removal(mech, chain.k_hat, rtol, ref)
            ), label
            start = 0
            for c in mech.all_closures:
                block = singular_values(chain.k_hat[start : start + c.rows])
                assert block[-1] >= dec.singular_values[-1] * (1 - 1e-12), label
                start += c.rows
    assert shortcut > 20


def test_output_motions_are_the_output_rows_times_the_motions(configurations):
    """The output rows' product with the closed chain's motions, without the rows: the product, to round-off."""
    from pinmob.analysis.chain.actuation import default_end_frames
    from pinmob.analysis.chain.closed_chain import closed_chain, output_motions, output_rows
    from pinmob.screw.rank import RTOL

    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        null = closed_chain(conf, RTOL).null  # type: ignore[arg-type]
        for frames in (default_end_frames(mech), ()):
            product = output_rows(conf, frames) @ null  # type: ignore[arg-type]
            mine = output_motions(conf, frames, null)  # type: ignore[arg-type]
            assert mine.shape == product.shape, label
            assert_allclose(mine, product, rtol=0, atol=1e-13 * max(1.0, float(np.abs(product).max(initial=0))))
            assert output_motions(conf, frames, null[:, :0]).shape == (product.shape[0], 0), label  # no motion


def test_lock_without_the_stacked_svd_is_the_stacked_svd(configurations):
    """Where the locked rates have full rank and the bound holds, idle is empty as the stacked SVD finds; elsewhere
    lock is that SVD. Every built-in model and Extended URDF robot, its actuators and each single joint, three rtol."""
    from pinmob.analysis.chain.actuation import default_end_frames, held_indices
    from pinmob.analysis.chain.closed_chain import closed_chain, output_rows, rates_of
    from pinmob.analysis.chain.locking import lock
    from pinmob.screw.rank import decide_rank

    shortcut = 0
    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        outs = output_rows(conf, default_end_frames(mech))  # type: ignore[arg-type]
        for rtol in (1e-9, 1e-6, 1e-3):
            null = closed_chain(conf, rtol).null  # type: ignore[arg-type]
            out = outs @ null
            m = null.shape[1]
            sets = [held_indices(mech, mech.actuated)] + [np.array([i]) for i in range(min(m, mech.model.nv))]
            for idx in sets:
                rates = rates_of(null, idx)
                split = lock(rates, lambda o=out: o, rtol, m)
                straight = decide_rank(np.vstack([rates, out]), rtol, m, at_least=1.0)
                assert split.idle.shape == (m, m - straight.rank), label
                locked = decide_rank(rates, rtol, m, at_least=1.0)
                assert split.rank_a == locked.rank and np.array_equal(split.locked, locked.null_space.T), label
                shortcut += split.rank_a == m and m > 0
    assert shortcut > 50


def test_stacked_error_is_each_closure_scaled_then_stacked(configurations):
    """The rows scaled once after stacking: bit for bit each closure's residual and Jacobian scaled, then stacked."""
    from pinmob.assembly.residual import closure_error, stacked_error

    for label, conf in configurations:
        mech = conf.mechanism  # type: ignore[attr-defined]
        model, data = mech.model, conf.data  # type: ignore[attr-defined]
        es, js = [], []
        for c in mech.all_closures:
            e, jac, lin = closure_error(model, data, c)
            s = np.where(lin, 1.0 / mech.length_scale, 1.0)
            es.append(s * e)
            js.append(s[:, None] * jac)
        e, jac = stacked_error(mech, model, data, mech.all_closures)
        if es:
            assert np.array_equal(e, np.concatenate(es)) and np.array_equal(jac, np.vstack(js)), label
        else:
            assert e.shape == (0,) and jac.shape == (0, model.nv), label


def test_closure_value_and_residual_norms_are_the_straightforward_ones(configurations):
    """closure_value is closure_error's residual and mask, bit for bit, for every closure type (a free body between
    two frames at random poses); the residual norms are np.linalg.norm's, on every closure and limb tip."""
    import pinocchio as pin

    from pinmob.assembly.residual import (
        closure_error,
        closure_residuals,
        closure_value,
        compute_kinematics,
        tip_residuals,
    )
    from pinmob.model.closure import CLOSURE_TYPES, make_closure

    rng = np.random.default_rng(12)
    model = pin.Model()
    body = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "free")
    model.addFrame(pin.Frame("a", 0, pin.exp6(rng.normal(size=6)), pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("b", body, pin.exp6(rng.normal(size=6)), pin.FrameType.OP_FRAME))
    data = model.createData()
    u, v = np.array([0.0, 0.6, 0.8]), np.array([1.0, 0.0, 0.0])
    for kind in CLOSURE_TYPES:
        axes = {"axis": u, "axis_b": v} if kind in ("universal", "perpendicular") else {"axis": u}
        closure = make_closure(model, kind, "a", "b", kind, **axes)  # an axis a type has not is not read
        for _ in range(5):
            compute_kinematics(model, data, pin.integrate(model, pin.neutral(model), rng.normal(size=6)))
            e, _, lin = closure_error(model, data, closure)
            value, mask = closure_value(model, data, closure)
            assert np.array_equal(value, e) and np.array_equal(mask, lin), kind
    for label, conf in configurations:
        mech, data = conf.mechanism, conf.data  # type: ignore[attr-defined]
        straight = {}
        for c in mech.all_closures:
            e, _, lin = closure_error(mech.model, data, c)
            straight[c.name] = (float(np.linalg.norm(e[lin])), float(np.linalg.norm(e[~lin])))
        assert closure_residuals(mech, data, mech.all_closures) == straight, label
        for limb in mech.limbs if mech.has_platform else ():
            e = pin.log6(data.oMf[mech.platform_id].actInv(data.oMf[limb.tip_id])).vector
            assert tip_residuals(mech, data)[limb.name] == (np.linalg.norm(e[:3]), np.linalg.norm(e[3:])), label


def test_a_kept_classification_is_the_classification_of_the_space(configurations):
    """The platform frame's motions on the closed chain, classified afresh, are what the report gives.

    The classification is kept per configuration and given to a later span of the same space (the report
    classifies the platform mobility first, then hands its classification to the platform frame). Each frame
    of each report (every body of the model asked for, spaces of one dimension at one configuration) is
    computed again in a fresh configuration, where nothing is kept: the same kinds and twists, on every
    built-in model and configuration and the example-parallel-robots. The paper's view at
    3-PUU-flat's 'flat-raised', a different space at the same configuration, stays its own: 3T1R, against 1T1R.
    """
    from pinmob.analysis.chain.mechanism_mobility import frame_mobility_at as frame_mobility

    checked = 0
    for label, conf in configurations:
        model = conf.mechanism.model
        bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
        report = pinmob.analyze(conf, frames=bodies)
        for frame in report.mechanism_mobility.frames:
            alone = frame_mobility(pinmob.Configuration(conf.mechanism, conf.q), frame.frame, report.rtol)
            assert frame.motion_type == alone.motion_type, label
            assert_allclose(frame.free_twists, alone.free_twists, atol=1e-9, err_msg=label)  # labels: 1e-10 dust
            checked += 1
    assert checked > 1000
    flat = pinmob.analyze(pinmob.load("3-PUU-flat"), "flat-raised", paper=True)
    assert (flat.motion_type, flat.paper.motion_type) == ("1T1R", "3T1R")


def test_joint_rates_of_one_component_joints_read_directly():
    """A one-component joint's rate read directly: the same names, values and order as the largest-component rule
    applied to every joint, on random rates (zeros and tiny ones among them) of every built-in model."""
    from pinmob.analysis.chain.joint_rates import RATE_TIE, joint_rates, velocity_segments

    def straightforward(mech: pinmob.Mechanism, dq: np.ndarray) -> dict[str, float]:
        big = float(np.max(np.abs(dq)))
        rates, out = (dq / big).tolist(), {}
        for name, start, stop in velocity_segments(mech):
            part = rates[start:stop]
            size = [abs(x) for x in part]
            if max(size) > 1e-6:  # the first component within RATE_TIE of the largest
                out[name] = round(part[next(k for k, x in enumerate(size) if x >= max(size) - RATE_TIE)], 6)
        return dict(sorted(out.items(), key=lambda kv: -float(f"{abs(kv[1]):.3g}")))

    rng = np.random.default_rng(13)
    for name in pinmob.builtin_models():
        mech = pinmob.load(name)
        for _ in range(20):
            dq = rng.normal(size=mech.model.nv) * 10.0 ** rng.integers(-8, 1, size=mech.model.nv)
            dq[rng.random(mech.model.nv) < 0.3] = 0.0
            dq[0] = 1.0
            assert list(joint_rates(mech, dq).items()) == list(straightforward(mech, dq).items()), name
