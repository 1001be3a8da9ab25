"""Fuzz kinds serve, codemodels and classes (driven by fuzz_campaign.py, whose docstring
says what each kind sends and what counts as a finding)."""

from __future__ import annotations

import contextlib
import json
import os
import random
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fuzz_markup import _must_be_model_error
from fuzz_models import _SAFE_DUMPER, _SAFE_LOADER, DH_SEEDS, ROOT, YAML_SEEDS, _paths, _seed_text

# ------------------------------------------------------------------ armdyn serve's endpoints
# Kind "serve": hostile sizes and timings against a real `armdyn serve` on 127.0.0.1 (one
# per worker process, started before the first input, with one grading worker and a
# throwaway SQLite file). Each input is one request (or one raw connection that stops,
# trickles or lies about its length); afterwards the answer must be below 500 (503 with
# Retry-After only for previews), and /api/health must answer 200 within 5 s. A 5xx, a
# dropped answer to a well-formed request or an unhealthy server is a finding.
SERVE_PATHS = ["/api/grade", "/api/preview", "/grade", "/instructor/login", "/instructor/logout", "/api/health"]
SERVE_IDS = ["x", "a" * 25, "ab%00cd", "..%2F..%2Fetc", "%C3%A9t%C3%A9", "%FF%FE", "A" * 4000, "%0d%0aX:y"]
_SERVE: dict = {}


def _serve_base() -> str:
    """The worker's server (started once; stopped when the worker exits)."""
    if "base" not in _SERVE:
        import atexit
        import shutil
        import socket
        import urllib.request

        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            port = sock.getsockname()[1]
        tmp = tempfile.mkdtemp(prefix="armdyn-fuzz-serve-")
        token = "fuzz-" + os.urandom(12).hex()
        cmd = [sys.executable, "-m", "armdyn", "serve", "--port", str(port), "--workers", "1"]
        db = os.environ.get("ARMDYN_FUZZ_SERVE_DB") or f"sqlite:///{tmp}/fuzz.db"  # e.g. a throwaway PostgreSQL
        cmd += ["--db", db, "--instructor-token", token, "--timeout", "10"]
        env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        atexit.register(lambda: (proc.terminate(), proc.wait(30), shutil.rmtree(tmp, ignore_errors=True)))
        base = f"http://127.0.0.1:{port}"
        for _ in range(600):  # at most 2 minutes
            try:
                with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
                    if r.status == 200:
                        break
            except OSError:
                time.sleep(0.2)
        else:
            raise RuntimeError("the fuzz server did not start")
        _SERVE.update(base=base, port=port, proc=proc)
    return _SERVE["base"]


def _serve_body(rng: random.Random) -> bytes:
    size = rng.choice([0, 1, 100, 10_000, 199_999, 200_001, 999_999, 1_000_001, 3_000_000])
    pieces = [b"$$", b"\\frac{", b"}", b"{", b"\x00", b"\xff", b"\n", b"---\nrobot: rp-arm\n---\n", b"\\tau_1 = "]
    piece = rng.choice(pieces) if rng.random() < 0.5 else os.urandom(rng.randint(1, 64))
    return (piece * (size // max(1, len(piece)) + 1))[:size]


def _serve_raw(port: int, rng: random.Random) -> None:
    """A connection that misbehaves: stops mid-head, trickles its head, lies about its
    length, sends an oversized head or broken chunks. The server may close it or answer
    4xx; it must stay healthy."""
    import socket

    how = rng.choice(["stop", "trickle", "short-body", "huge-head", "bad-chunks", "garbage"])
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        head = b"POST /api/grade?wait=0 HTTP/1.1\r\nHost: x\r\nContent-Type: text/markdown\r\n"
        if how == "stop":
            sock.sendall(head[: rng.randint(1, len(head))])
        elif how == "trickle":  # at most 1 s of trickling
            for i in range(0, len(head), 8):
                sock.sendall(head[i : i + 8])
                time.sleep(0.02)
        elif how == "short-body":
            sock.sendall(head + b"Content-Length: 5000\r\n\r\n" + b"$$x=1$$")
        elif how == "huge-head":
            sock.sendall(head + b"X-Big: " + b"a" * rng.choice([70_000, 200_000]) + b"\r\n\r\n")
        elif how == "bad-chunks":
            sock.sendall(head + b"Transfer-Encoding: chunked\r\n\r\nzz\r\nabc\r\n0\r\n\r\n")
        else:
            sock.sendall(os.urandom(rng.randint(1, 4096)))
        sock.settimeout(1.0)
        try:
            answer = sock.recv(64)
        except OSError:
            answer = b""
    if answer.startswith(b"HTTP/1.1 5") and not answer.startswith(b"HTTP/1.1 503"):
        raise AssertionError(f"raw {how}: {answer!r}")


def run_serve(seed: int, rng: random.Random):
    import http.client
    import urllib.parse

    base = _serve_base()
    port = _SERVE["port"]
    if rng.random() < 0.25:
        _serve_raw(port, rng)
    else:
        if rng.random() < 0.3:
            sid = rng.choice(SERVE_IDS)
            path = rng.choice([f"/api/submissions/{sid}", f"/submissions/{sid}", f"/submissions/{sid}/report.html"])
            method, body = "GET", b""
        else:
            path, method, body = rng.choice(SERVE_PATHS), "POST", _serve_body(rng)
        query = {
            "wait": rng.choice(["0", "-1", "nan", "inf", "1e308", "0.1"]),
            "student": rng.choice(["Ada", "a\x00b", "\u202e" * 50, "x" * 5000]),
            "robot": rng.choice(["rp-arm", "../../etc/passwd", "rp\x00arm", ""]),
        }
        kind = rng.choice(["text/markdown", "text/plain", "application/x-www-form-urlencoded", "multipart/form-data"])
        headers = {"Content-Type": kind, "Authorization": rng.choice(["", "Bearer " + "x" * 300, "Bearer short"])}
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        try:
            conn.request(method, path + "?" + urllib.parse.urlencode(query), body=body, headers=headers)
            r = conn.getresponse()
            r.read()
            status, retry = r.status, r.getheader("retry-after")
        except (ConnectionResetError, BrokenPipeError):
            status, retry = 413, None  # the server may close on a body past its limit
        finally:
            conn.close()
        if status >= 500 and not (status == 503 and path == "/api/preview" and retry):
            raise AssertionError(f"{method} {path} ({len(body)} bytes, {kind}): {status}")
    import urllib.request

    with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
        if r.status != 200:
            raise AssertionError(f"/api/health {r.status} after seed {seed}")


PREPARE = {"serve": _serve_base}  # kinds whose set-up must not count against an input's timeout

# ------------------------------------------------------------------ model files that run code, hostile classes
# Kinds "codemodels" and "classes" (registered in IO_KINDS): each input gets a fresh
# folder and a marker path in it that the input's payload would create if any of it ran;
# the input must end in a result or a ModelError within SECURITY_SECONDS, and the marker
# must not exist afterwards.

#: ways a model file could reach code: xacro's eval (with the vars()/type() bypass of its
#: ``__`` filter), includes, YAML tags that construct objects, Python in DH expressions
CODE_SNIPPETS = [
    "${python.vars(python.type(python.vars(python.type(xacro.arg))['__globals__']))['__get__']"
    "(python.vars(python.type(xacro.arg))['__globals__'], xacro.arg)['os'].mkdir('MARKER')}",
    "${__import__('os').mkdir('MARKER')}",
    "$(eval __import__('os').mkdir('MARKER'))",
    "__import__('os').mkdir('MARKER')",
    "eval(\"__import__('os').mkdir('MARKER')\")",
    "(lambda: 0)()",
    "().__class__.__base__.__subclasses__()",
    "m1.__class__",
    "os.mkdir('MARKER')",
    "exec('1')",
    "getattr(m1, 'x')",
]
CODE_TAGS = [
    "!!python/object/apply:os.mkdir ['MARKER']",
    "!!python/name:os.mkdir",
    "!!python/object/new:os.mkdir ['MARKER']",
    "!!python/module:os",
    "!<tag:yaml.org,2002:python/object/apply:os.mkdir> ['MARKER']",
]
URDF_INCLUDES = [
    '<xacro:include filename="MARKER.xacro"/>',
    '<mesh filename="package://armdyn/MARKER"/>',
    '<mesh filename="file://MARKER"/>',
    '<?xml-stylesheet href="file://MARKER"?>',
    '<xi:include href="file://MARKER" xmlns:xi="http://www.w3.org/2001/XInclude"/>',
    '<!DOCTYPE r [<!ENTITY e SYSTEM "file://MARKER">]><robot name="&e;"/>',
]


def _planted(marker: str, text: str) -> str:
    return text.replace("MARKER", marker)


def run_codemodels(seed: int, rng: random.Random):
    """A model file that tries to run code: a snippet as a YAML field's value (frame model
    or DH table), a tag as a value, an include or URI in a URDF, or a whole ``.xacro``
    file; loaded through ``armdyn.load`` untrusted (never with the opt-in)."""
    import yaml

    import armdyn

    with tempfile.TemporaryDirectory() as tmp:
        marker = os.path.join(tmp, "MARKER-RAN")
        r = rng.random()
        if r < 0.45:
            base = rng.choice(YAML_SEEDS + DH_SEEDS)
            doc = yaml.load(_seed_text(base), Loader=_SAFE_LOADER)
            container, key = rng.choice(list(_paths(doc)))
            container[key] = "FUZZ_VALUE_MARKER"
            text = yaml.dump(doc, Dumper=_SAFE_DUMPER, sort_keys=False, allow_unicode=True, width=10**6)
            value = (
                rng.choice(CODE_TAGS) if rng.random() < 0.3 else json.dumps(_planted(marker, rng.choice(CODE_SNIPPETS)))
            )
            path = os.path.join(tmp, "m.yaml")
            Path(path).write_text(text.replace("FUZZ_VALUE_MARKER", _planted(marker, value), 1))
        elif r < 0.75:
            text = _seed_text("iiwa14.urdf")
            cut = rng.choice([m.end() for m in re.finditer(r"<robot[^>]*>|</link>|</joint>", text)])
            piece = rng.choice(URDF_INCLUDES + CODE_SNIPPETS)
            text = text[:cut] + _planted(marker, piece) + text[cut:]
            path = os.path.join(tmp, rng.choice(["m.urdf", "m.urdf", "m.xacro"]))
            Path(path).write_text(text)
        else:
            lines = [f'<link name="l{k}"/>' for k in range(3)]
            lines.insert(rng.randrange(len(lines) + 1), f'<link name="{_planted(marker, rng.choice(CODE_SNIPPETS))}"/>')
            path = os.path.join(tmp, "m.xacro")
            Path(path).write_text(
                '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">' + "".join(lines) + "</robot>"
            )
        try:
            _must_be_model_error(lambda: armdyn.load(path), f"seed {seed}: {os.path.basename(path)}")
        finally:
            if os.path.exists(marker) or os.path.exists(marker + ".xacro"):
                raise AssertionError(f"seed {seed}: a model file ran code ({os.path.basename(path)})")


#: front matters of hostile submissions in a class folder
CLASS_FRONTS = [
    "student: bob\n",
    "student: ../../x\n",
    "student: a_b\n",
    "variant: bob\n",
    "robot: ../outside.yaml\n",
    "robot: /etc/hostname\n",
    "robot: attachment.xacro\n",
    "robot: link.yaml\n",
    "robot: rp-arm\n",
    "robot: planar-2r\n",
    "student: &a [*a]\n",
    "student: !!python/object/apply:os.mkdir ['MARKER']\n",
]
CLASS_NAMES = ["alice", "bob", "a b", "a_b", "Ada", "ada", "x.y", "-rf", "=cmd", "\u00e9", "e\u0301", "..x"]


def run_classes(seed: int, rng: random.Random):
    """A class folder of hostile submissions: spoofed ``student:`` and ``variant:``, names
    whose reports collide, models named by paths out of the folder, a ``.xacro`` payload,
    symbolic links (to files outside, to /dev/zero, to a FIFO) and FIFOs. :func:`discover`
    must keep each student's identity to the file name, follow no link, give every task
    its own report name and a model that is bundled or a regular file in the folder; and
    no payload may run (loading each task's model untrusted)."""
    import armdyn
    from armdyn.course.batch import discover, safe_file_name
    from armdyn.errors import ModelError

    with tempfile.TemporaryDirectory() as tmp:
        marker = os.path.join(tmp, "MARKER-RAN")
        subs = os.path.join(tmp, "subs")
        variants = os.path.join(tmp, "variants")
        os.makedirs(subs)
        Path(tmp, "outside.yaml").write_text(_seed_text("rp-arm"))
        Path(subs, "attachment.xacro").write_text(
            '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="'
            + _planted(marker, CODE_SNIPPETS[0])
            + '"/></robot>'
        )
        for name in rng.sample(CLASS_NAMES, rng.randint(1, len(CLASS_NAMES))):
            ext = rng.choice([".md", ".md", ".yaml"])
            path = os.path.join(subs, name + ext)
            r = rng.random()
            if r < 0.1:
                os.symlink(os.path.join(tmp, "outside.yaml"), path)
            elif r < 0.15:
                os.symlink("/dev/zero", path)
            elif r < 0.2:
                os.mkfifo(path)
            else:
                front = "".join(rng.sample(CLASS_FRONTS, rng.randint(0, 3)))
                front = _planted(marker, front)
                text = f"---\n{front}---\n$$\\tau_1 = 0$$\n" if ext == ".md" else front + "steps: {}\n"
                Path(path).write_text(text)
        if rng.random() < 0.5:
            os.symlink(os.path.join(tmp, "outside.yaml"), os.path.join(subs, "link.yaml"))
        if rng.random() < 0.5:
            for vid in ("alice", "bob"):
                os.makedirs(os.path.join(variants, vid))
                Path(variants, vid, "model.yaml").write_text(_seed_text("rp-arm"))
        found = discover(subs, variants if os.path.isdir(variants) else None)
        reports = set()
        for t in found.tasks:
            stem = os.path.splitext(os.path.basename(t.path))[0]
            if t.student != stem or os.path.islink(t.path):
                raise AssertionError(f"seed {seed}: {t.path} graded as {t.student!r}")
            report = safe_file_name(t.student).casefold()
            if report in reports:
                raise AssertionError(f"seed {seed}: two tasks write {report}.html")
            reports.add(report)
            if t.robot and os.sep in t.robot:
                inside = os.path.dirname(t.robot) in (subs, os.path.join(variants, t.variant or ""))
                if not inside or os.path.islink(t.robot):
                    raise AssertionError(f"seed {seed}: {t.path} graded against {t.robot}")
            if t.robot:
                with contextlib.suppress(ModelError):
                    armdyn.load(t.robot, strict=False)
        if os.path.exists(marker):
            raise AssertionError(f"seed {seed}: a class folder ran code")


IO_KINDS = {"codemodels": run_codemodels, "classes": run_classes}
