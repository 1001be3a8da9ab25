"""Untrusted models and submissions: names never run code, outputs go only to regular
files, bad numeric arguments are errors naming the argument (hostile model files and
expressions: test_security_hostile_models.py).

Every expected value comes from somewhere else than the code under test: generated code
is checked against the Rust core's rnea, refusals by the one-line message and by what
is (not) on disk."""

from __future__ import annotations

import importlib.util
import math
import os
import re
import socket
import stat
import warnings
from pathlib import Path

import numpy as np
import pytest
from security_support import two_link_yaml

import armdyn
from armdyn import numeric, printing
from armdyn.cli import main
from armdyn.io.urdf import load_urdf
from armdyn.io.yaml import load_yaml_string
from armdyn.printing.safe_names import comment_text, identifier_base


# ------------------------------------------------------------------ 1. names into generated code
def two_link_urdf(robot: str, j1: str, link: str) -> bytes:
    from xml.sax.saxutils import quoteattr

    r, j, lk = (quoteattr(x) for x in (robot, j1, link))
    inertial = (
        '<inertial><origin xyz="0.3 0.05 0"/><mass value="1.3"/>'
        '<inertia ixx="0.02" iyy="0.05" izz="0.06" ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    return f"""<robot name={r}>
  <link name="base"/>
  <link name={lk}>{inertial}</link>
  <link name="link2">{inertial}</link>
  <joint name={j} type="continuous"><parent link="base"/><child link={lk}/><axis xyz="0 0 1"/></joint>
  <joint name="q2" type="continuous"><parent link={lk}/><child link="link2"/>
    <origin xyz="0.7 0 0.1"/><axis xyz="0 1 0"/></joint>
</robot>""".encode()


def payloads(canary: Path) -> list[str]:
    """Names that end a C comment or a Python docstring and then create ``canary``."""
    c = (
        "x */ __attribute__((constructor)) static void armdyn_pwn(void) { extern int system(const char *); "
        f'system("touch {canary}"); }} /* '
    )
    py = f'x """ + str(open({str(canary)!r}, "w").close()) + """'
    py2 = f"x ''' + str(open({str(canary)!r}, 'w').close()) + '''"
    trigraph = f'x *??/\n/ int armdyn_pwn = system("touch {canary}"); /*'.replace("\n", " ")
    return [c, py, py2, trigraph, c + py]


def _import_file(path: Path):
    spec = importlib.util.spec_from_file_location(f"armdyn_generated_{abs(hash(str(path)))}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _check_header_is_safe(source: str) -> None:
    header = source.split("#include", 1)[0] if source.startswith("/*") else source.split('"""', 2)[1]
    assert all(" " <= ch <= "~" or ch == "\n" for ch in header), "non-ASCII in the header"
    body = header[2:] if header.startswith("/*") else header
    assert "*/" not in body.rstrip().removesuffix("*/") and '"""' not in body and "\\" not in body and "??" not in body


STATE = (np.array([0.3, -0.7]), np.array([0.4, 1.1]), np.array([-0.5, 0.9]))


def _rust_tau(robot):
    return armdyn.rnea(robot, *STATE)


@pytest.mark.parametrize("lang", ["c", "python", "numpy"])
@pytest.mark.parametrize("fmt", ["yaml", "urdf"])
def test_hostile_names_do_not_run_code(tmp_path, lang, fmt):
    canary = tmp_path / "canary"
    for k, name in enumerate(payloads(canary)):
        if fmt == "yaml":
            robot = load_yaml_string(two_link_yaml(name, j1=name + "j", link=name + "l"))
        else:
            robot = load_urdf(two_link_urdf(name, name + "j", name + "l"))
        code = printing.codegen(robot, what=("tau",), lang=lang)
        _check_header_is_safe(code.source)
        work = tmp_path / f"{lang}{k}"
        work.mkdir()
        if lang == "c":
            lib = printing.compile(code, directory=work)  # dlopen runs any constructor
            tau = lib.tau(*STATE)
        else:
            (path,) = printing.write_files([code], work)
            module = _import_file(Path(path))
            tau = np.asarray(getattr(module, code.functions["tau"])(*STATE))
        assert not canary.exists(), f"{lang}: a name ran code: {name!r}"
        np.testing.assert_allclose(tau, _rust_tau(robot), rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("lang", ["c", "python", "numpy"])
def test_names_equal_under_nfkc_stay_two_variables(tmp_path, lang):
    """q1 and the fullwidth q1 are one identifier to Python (NFKC): tau was wrong."""
    robot = load_yaml_string(two_link_yaml("nfkc", "q1", "\uff51" + "1"))
    assert robot.coordinate_names == ["q1", "\uff51" + "1"]
    code = printing.codegen(robot, what=("tau", "M"), lang=lang)
    assert code.source.isascii()
    if lang == "c":
        lib = printing.compile(code, directory=tmp_path)
        tau, M = lib.tau(*STATE), lib.M(STATE[0])
    else:
        (path,) = printing.write_files([code], tmp_path)
        module = _import_file(Path(path))
        tau = np.asarray(getattr(module, code.functions["tau"])(*STATE))
        M = np.asarray(getattr(module, code.functions["M"])(STATE[0])).reshape(2, 2)
    np.testing.assert_allclose(tau, _rust_tau(robot), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(M, armdyn.crba(robot, STATE[0]), rtol=1e-10, atol=1e-10)
    assert "<U+FF51>1 -> " in code.source  # the mapping is listed in the header


def test_comment_text_and_identifiers_invariants():
    rng = np.random.default_rng(5)
    alphabet = list("*/\"\\?'\n\t\x00 ab_1") + ["\uff51", "\u202e", "\u00e9", "\ud7ff"]
    for _ in range(3000):
        s = "".join(rng.choice(alphabet, size=int(rng.integers(0, 12))))
        t = comment_text(s)
        assert all(" " <= ch <= "~" for ch in t), (s, t)
        for bad in ("*/", "/*", '"', "\\", "?"):
            assert bad not in t, (s, t)
        ident = identifier_base(s)
        assert re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", ident), (s, ident)
    assert comment_text("q1 arm-2 (left)") == "q1 arm-2 (left)"  # ordinary names unchanged


# ------------------------------------------------------------------ 2. output paths
def _grade_args(tmp_path, html: str) -> list[str]:
    sub = tmp_path / "sub.yaml"
    sub.write_text("robot: rp-arm\nsteps: {T: '0'}\n")
    return ["grade", str(sub), "--html", html]


def _special_files(tmp_path) -> dict:
    """Non-regular files to write onto: FIFO, socket, directory, and a character device
    when the process may create one (root)."""
    out = {}
    os.mkfifo(tmp_path / "fifo")
    out["fifo"] = tmp_path / "fifo"
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(tmp_path / "sock"))
    sock.close()
    out["socket"] = tmp_path / "sock"
    (tmp_path / "dir").mkdir()
    out["directory"] = tmp_path / "dir"
    try:
        os.mknod(tmp_path / "dev", stat.S_IFCHR | 0o644, os.makedev(1, 3))
        out["character device"] = tmp_path / "dev"
    except PermissionError:
        pass
    return out


def test_html_refuses_non_regular_targets(tmp_path, capsys):
    for kind, path in _special_files(tmp_path).items():
        before = os.lstat(path)
        assert main(_grade_args(tmp_path, str(path))) == 2, kind
        err = capsys.readouterr().err
        assert err.startswith(f"armdyn: error: {path}: is a") and err.count("\n") == 1, err
        after = os.lstat(path)
        assert stat.S_IFMT(after.st_mode) == stat.S_IFMT(before.st_mode) and after.st_ino == before.st_ino, kind


def test_html_read_only_empty_and_symlinks(tmp_path, capsys):
    ro = tmp_path / "ro.html"
    ro.write_text("keep")
    ro.chmod(0o444)
    assert main(_grade_args(tmp_path, str(ro))) == 2
    assert "read-only" in capsys.readouterr().err and ro.read_text() == "keep"  # root too
    assert main(_grade_args(tmp_path, "")) == 2
    assert "output path is empty" in capsys.readouterr().err
    target = tmp_path / "real.html"
    target.write_text("old")
    target.chmod(0o640)
    link = tmp_path / "link.html"
    link.symlink_to(target)
    assert main(_grade_args(tmp_path, str(link))) in (0, 1)
    capsys.readouterr()
    assert link.is_symlink() and "<html" in target.read_text().lower()
    assert stat.S_IMODE(target.stat().st_mode) == 0o640  # an existing file keeps its mode
    dangling = tmp_path / "dangling.html"
    dangling.symlink_to(tmp_path / "nowhere" / "x.html")
    assert main(_grade_args(tmp_path, str(dangling))) == 2
    assert "symbolic link" in capsys.readouterr().err and dangling.is_symlink()


def test_codegen_out_onto_a_file_and_umask(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert main(["codegen", "planar-2r", "--what", "tau", "--out", str(afile)]) == 2
    err = capsys.readouterr().err
    assert "not a directory" in err and "internal error" not in err and afile.read_text() == "x"
    old = os.umask(0o022)
    try:
        assert main(["codegen", "planar-2r", "--what", "tau", "--out", str(tmp_path / "gen")]) == 0
        with open(tmp_path / "reference", "w"):  # what open() makes under the same umask
            pass
    finally:
        os.umask(old)
    capsys.readouterr()
    (made,) = (tmp_path / "gen").iterdir()
    assert stat.S_IMODE(made.stat().st_mode) == stat.S_IMODE((tmp_path / "reference").stat().st_mode) == 0o644


# ------------------------------------------------------------------ 3. numeric arguments
@pytest.fixture(scope="module")
def arm():
    return load_yaml_string(two_link_yaml("arm"))


def _every_threads_call(robot):
    """Every function of armdyn that takes ``threads``, as ``name -> call(threads)``."""
    from armdyn import numeric
    from armdyn.simulate import simulate

    q = np.zeros(robot.dof)
    link = list(robot.links)[-1]
    calls = {
        name: (lambda t, f=getattr(numeric, name), k=k: f(robot, *[q] * k, threads=t))
        for name, k in [
            ("rnea", 3),
            ("crba", 1),
            ("aba", 3),
            ("gravity", 1),
            ("bias", 2),
            ("coriolis_matrix", 2),
            ("kinetic_energy", 2),
            ("potential_energy", 1),
            ("forward_kinematics", 1),
            ("rnea_derivatives", 3),
            ("aba_derivatives", 3),
            ("minverse", 1),
            ("gravity_derivatives", 1),
            ("regressor", 3),
        ]
    }
    calls["jacobian"] = lambda t: numeric.jacobian(robot, q, link, threads=t)
    calls["jacobian_dot"] = lambda t: numeric.jacobian_dot(robot, q, q, link, threads=t)
    calls["simulate"] = lambda t: simulate(robot, q, dt=0.01, steps=2, threads=t)
    return calls


@pytest.mark.parametrize("threads", [True, False, np.bool_(True), 1.5, "2", np.float64(2.0)])
def test_threads_that_is_not_an_integer_is_a_type_error(arm, threads):
    """Before: rnea_derivatives, aba_derivatives, minverse (the Rust entries, which read
    ``threads`` as an integer) and simulate ran threads=True as 1."""
    calls = _every_threads_call(arm)
    assert len(calls) == 17
    for name, call in calls.items():
        with pytest.raises(TypeError, match="^threads: expected None or an integer from 1 to 256, got "):
            call(threads)


@pytest.mark.parametrize("threads", [2**64, 0, -1, 257, np.int64(0)])
def test_threads_out_of_range_is_a_value_error(arm, threads):
    for name, call in _every_threads_call(arm).items():
        with pytest.raises(ValueError, match="^threads: expected None or an integer from 1 to 256, got "):
            call(threads)


def test_threads_that_is_a_count_runs(arm):
    """Batched with 2 threads (also NumPy's integer) as one row at a time."""
    q = np.array([[0.1, -0.4], [0.7, 0.2], [-1.0, 0.5]])
    for threads in (2, np.int64(2)):
        for name in ("rnea", "rnea_derivatives"):
            f = getattr(armdyn.numeric, name)
            batch = f(arm, q, q, q, threads=threads)
            rows = [f(arm, r, r, r) for r in q]
            got = batch[0] if isinstance(batch, tuple) else batch
            want = np.stack([r[0] if isinstance(r, tuple) else r for r in rows])
            np.testing.assert_array_equal(got, want)
    np.testing.assert_allclose(armdyn.minverse(arm, q, threads=2)[1], np.linalg.inv(armdyn.crba(arm, q[1])), atol=1e-12)


def test_threads_in_dask_functions(arm):
    da = pytest.importorskip("dask.array")
    from armdyn import dask as armdyn_dask

    q = da.zeros((4, 2), chunks=2)
    for name, k in (("rnea", 3), ("aba", 3), ("crba", 1), ("rnea_derivatives", 3), ("minverse", 1)):
        with pytest.raises(TypeError, match="^threads: "):
            getattr(armdyn_dask, name)(arm, *[q] * k, threads=True)
    with pytest.raises(TypeError, match="^threads: "):
        armdyn_dask.simulate(arm, np.zeros((2, 2)), dt=0.01, steps=2, threads=True)


def test_overflow_is_an_error_not_nan_or_singular(arm):
    q = np.array([0.3, -0.2])
    with pytest.raises(ValueError, match=r"^rnea: the result overflows float64.*max \|qd\| = 1e\+300"):
        armdyn.rnea(arm, q, np.array([1e300, 1e300]), np.zeros(2))
    with pytest.raises(ValueError, match=r"^aba: the result overflows float64") as info:
        armdyn.aba(arm, q, np.zeros(2), np.array([1e308, -1e308]))
    assert "singular" not in str(info.value)
    M = armdyn.crba(arm, q)  # the same M at moderate torques: the reference is M^-1 (tau - h)
    tau = np.array([1e5, -2e5])
    want = np.linalg.solve(M, tau - armdyn.bias(arm, q, np.zeros(2)))
    np.testing.assert_allclose(armdyn.aba(arm, q, np.zeros(2), tau), want, rtol=1e-10)


def test_overflow_in_every_velocity_product(arm):
    """qd = 1e200 squares to 1e400 in the velocity products: every function quadratic in qd
    reports an overflow (naming itself), one state or a batch, and the compiled model raises
    FloatingPointError rather than handing back inf or NaN."""
    q, qd = np.array([0.3, -0.2]), np.array([1e200, -1e200])
    for name, call in (
        ("bias", lambda q, qd: armdyn.bias(arm, q, qd)),
        ("kinetic_energy", lambda q, qd: armdyn.kinetic_energy(arm, q, qd)),
        ("regressor", lambda q, qd: numeric.regressor(arm, q, qd, np.zeros_like(q))),
    ):
        for qs, qds in ((q, qd), (np.tile(q, (3, 1)), np.tile(qd, (3, 1)))):
            with pytest.raises(ValueError, match=rf"^{name}: the result overflows float64"):
                call(qs, qds)
    # C(q, qd) is linear in qd: no overflow at 1e200
    assert np.isfinite(armdyn.coriolis_matrix(arm, q, qd)).all()
    with pytest.raises(FloatingPointError, match="not finite"):
        armdyn.compile_model(arm).rnea(q, qd, np.zeros(2))
    # moderate speeds: the same functions are finite and agree with each other (C qd = h - g)
    qd = np.array([3.0, -2.0])
    h, g = armdyn.bias(arm, q, qd), armdyn.gravity(arm, q)
    np.testing.assert_allclose(armdyn.coriolis_matrix(arm, q, qd) @ qd, h - g, rtol=1e-12, atol=1e-12)


def test_simulate_arguments(arm):
    from armdyn.simulate import PD, simulate

    q0 = np.array([0.1, 0.2])
    for bad in (True, np.bool_(True)):
        with pytest.raises(ValueError, match="^dt must be"):
            simulate(arm, q0, dt=bad, steps=2)
        with pytest.raises(ValueError, match="^duration must be"):
            simulate(arm, q0, dt=0.01, duration=bad)
        with pytest.raises(ValueError, match="^steps must be"):
            simulate(arm, q0, dt=0.01, steps=bad)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a ComplexWarning would be an error here, so would pass silently before
        with pytest.raises(ValueError, match="complex"):
            simulate(arm, q0, dt=0.01, steps=2, torque=lambda t, q, qd: np.array([1j, 0.0]))
    with pytest.raises(ValueError, match=r"^controller.kp contains NaN or inf$"):
        simulate(arm, q0, dt=0.01, steps=2, controller=PD(kp=math.nan, kd=1.0, target=q0))


def test_cli_duration_not_a_whole_number_of_steps(capsys):
    code = main(["simulate", "ur5", "--duration", "0.0105", "--dt", "0.001", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--duration 0.0105 is not a whole number of steps of --dt 0.001" in err, err
