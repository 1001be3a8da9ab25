"""The deadline rush of ``bench_serve.py --roster N``: a class of N students, each with
their own variant (``armdyn exercise make``) and personal link (``armdyn links``),
submitting to ``armdyn serve --roster --deadline`` within a window around the deadline.

Each student opens their link (a session cookie), loads ``/me``, posts their variant's
worked solution (every third one with a slip injected) to ``/api/grade?wait=0`` and
polls ``/api/submissions/{id}`` until the verdict, noting the queue ``position`` shown
while it waits. At most ``concurrency`` requests are open at a time. After the run,
every text is graded again in this process against its variant's ``model.yaml``
(``armdyn.grade``) and compared step by step with the server's verdict.
"""

from __future__ import annotations

import csv
import http.cookiejar
import json
import os
import random
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
LATE_SHARE = 0.2  # the last fifth of the window is after the deadline


def make_class(tmp: Path, n: int, seed: int) -> tuple[list[str], float]:
    """roster.csv and ``armdyn exercise make rp`` into tmp/variants; (ids, seconds)."""
    ids = [f"s{i:03d}" for i in range(n)]
    with open(tmp / "roster.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["id", "name"])
        w.writerows([i, f"Student {i}"] for i in ids)
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "armdyn", "exercise", "make", "rp", "--roster", str(tmp / "roster.csv")]
    subprocess.run([*cmd, "--seed", str(seed), "--out", str(tmp / "variants")], env=ENV, check=True, timeout=3600)
    return ids, time.perf_counter() - t0


def texts(tmp: Path, ids: list[str], seed: int) -> dict[str, tuple[str, bool]]:
    """Each student's derivation: their variant's worked solution, every third with one slip."""
    import numpy as np

    from armdyn.course.solution import inject_slip, solution_markdown, solution_steps
    from armdyn.io.yaml import load_yaml_string

    rng = np.random.default_rng(seed)
    out = {}
    for k, sid in enumerate(ids):
        folder = tmp / "variants" / sid
        text = (folder / "solution.md").read_text(encoding="utf-8")
        if k % 3 == 1:
            robot = load_yaml_string((folder / "model.yaml").read_text(encoding="utf-8"), f"{sid}/model.yaml")
            steps, _ = inject_slip(solution_steps(robot), rng, robot.q)
            front = {"robot": "model.yaml", "method": "both", "student": sid, "variant": sid}
            text = solution_markdown(robot, steps, front, f"Solution of exercise {sid}, by {sid}")
        out[sid] = (text, k % 3 == 1)
    return out


def links(tmp: Path, db: str, base: str) -> dict[str, str]:
    cmd = [sys.executable, "-m", "armdyn", "links", "--roster", str(tmp / "roster.csv")]
    cmd += ["--exercises", str(tmp / "variants"), "--db", db, "--base-url", base, "--out", str(tmp / "links.csv")]
    subprocess.run(cmd, env=ENV, check=True, timeout=600)
    with open(tmp / "links.csv", newline="") as fh:
        return {r["id"]: r["link"] for r in csv.DictReader(fh)}


def serve(tmp: Path, port: int, db: str, deadline: float, workers: int) -> subprocess.Popen:
    when = datetime.fromtimestamp(deadline, timezone.utc).isoformat(timespec="seconds")
    cmd = [sys.executable, "-m", "armdyn", "serve", "--port", str(port), "--workers", str(workers), "--db", db]
    cmd += ["--roster", str(tmp / "roster.csv"), "--exercises", str(tmp / "variants"), "--deadline", when]
    log = open(tmp / "serve.log", "w")  # noqa: SIM115 - closed with the process
    proc = subprocess.Popen(cmd, env=ENV, stderr=log, stdout=log)
    base = f"http://127.0.0.1:{port}"
    for _ in range(900):
        try:
            with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
                if r.status == 200:
                    return proc
        except OSError:
            pass
        if proc.poll() is not None:
            raise SystemExit(f"armdyn serve ended: see {tmp / 'serve.log'}")
        time.sleep(0.2)
    proc.kill()
    raise SystemExit("the server did not become ready")


class Student:
    """One student's browser: a cookie jar, and requests bounded by the class's semaphore."""

    def __init__(self, sid: str, gate: threading.Semaphore):
        self.sid, self.gate = sid, gate
        self.opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(http.cookiejar.CookieJar()))

    def send(self, req, tries: int = 30) -> tuple[int, bytes]:
        for k in range(tries):
            try:
                with self.gate, self.opener.open(req, timeout=120) as r:
                    return r.status, r.read()
            except urllib.error.HTTPError as err:
                if err.code != 503 or k == tries - 1:
                    raise
                time.sleep(float(err.headers.get("Retry-After") or 2))
        raise AssertionError("unreachable")

    def hand_in(self, link: str, base: str, text: str) -> dict:
        status, page = self.send(link)  # the link redirects to /me with the session cookie
        if status != 200 or b"Log out" not in page and b"logout" not in page:
            raise RuntimeError(f"{self.sid}: /me did not open from the personal link ({status})")
        req = urllib.request.Request(
            f"{base}/api/grade?wait=0", data=text.encode(), method="POST", headers={"content-type": "text/markdown"}
        )
        sent = time.time()
        _, raw = self.send(req)
        body, positions = json.loads(raw), []
        for _ in range(7200):  # bounded: at most two hours of polling
            if body["status"] in ("done", "failed"):
                break
            if body.get("position") is not None:
                positions.append(body["position"])
            time.sleep(1.0)
            body = json.loads(self.send(f"{base}/api/submissions/{body['id']}")[1])
        return {"body": body, "sent": sent, "seconds": time.time() - sent, "positions": positions}


def rush(base: str, link_of: dict, text_of: dict, at: dict, concurrency: int) -> tuple[dict, list[str]]:
    """Each student hands in at their time ``at[sid]`` (Unix seconds); (results by id, errors)."""
    gate = threading.Semaphore(concurrency)
    results, errors, lock = {}, [], threading.Lock()

    def one(sid: str) -> None:
        time.sleep(max(0.0, at[sid] - time.time()))
        try:
            out = Student(sid, gate).hand_in(link_of[sid], base, text_of[sid][0])
        except Exception as err:  # noqa: BLE001 - counted as lost
            with lock:
                errors.append(f"{sid}: {err}")
            return
        with lock:
            results[sid] = out

    threads = [threading.Thread(target=one, args=(sid,)) for sid in at]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results, errors


def check(tmp: Path, results: dict, text_of: dict, deadline: float) -> dict:
    """The server's verdicts against ``armdyn.grade`` in this process, and the late marks."""
    from armdyn.grading import grade
    from armdyn.grading.reader import read_markdown

    wrong, late_wrong = [], []
    for sid, r in sorted(results.items()):
        b = r["body"]
        mine = json.loads(
            grade(
                read_markdown(f"{sid}.md", text_of[sid][0]), robot=str(tmp / "variants" / sid / "model.yaml")
            ).to_json()
        )
        same = (
            b["status"] == "done"
            and b.get("first_wrong") == mine["first_wrong"]
            and b.get("tau_correct") == mine["tau_correct"]
            and [(s["name"], s["status"]) for s in b.get("steps", [])]
            == [(s["name"], s["status"]) for s in mine["steps"]]
        )
        if not same:
            wrong.append(sid)
        if bool(b.get("late")) != (b["created_at"] > deadline):
            late_wrong.append(sid)
    return {"wrong": wrong, "late_wrong": late_wrong}


def run_rush(args, start_postgres) -> None:
    import tempfile

    from bench_serve import pct

    with tempfile.TemporaryDirectory(prefix="armdyn-bench-rush-") as name:
        tmp = Path(name)
        ids, make_s = make_class(tmp, args.roster, args.seed)
        text_of = texts(tmp, ids, args.seed)
        pg = start_postgres() if args.postgres else None
        db = pg.url if pg else f"sqlite:///{tmp}/rush.db"
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        base = f"http://127.0.0.1:{port}"
        link_of = links(tmp, db, base)
        # the window starts once the server is up; the deadline is LATE_SHARE before its end
        t_ready_guess = time.time() + 60
        deadline = float(int(t_ready_guess + (1 - LATE_SHARE) * args.window))
        proc = serve(tmp, port, db, deadline, args.workers)
        load0 = os.getloadavg()[0]
        start = max(time.time() + 1, deadline - (1 - LATE_SHARE) * args.window)
        rnd = random.Random(args.seed)
        span = deadline + LATE_SHARE * args.window - start
        # uniform, or a rush: Beta(5, 2), densest at the deadline (80% of the window), a third after it
        draw = (lambda: rnd.uniform(0, 1)) if args.arrivals == "uniform" else (lambda: rnd.betavariate(5, 2))
        at = {sid: start + draw() * span for sid in ids}
        t0 = start
        try:
            results, errors = rush(base, link_of, text_of, at, args.concurrency)
        finally:
            wall = time.time() - t0
            load1 = os.getloadavg()[0]
            proc.send_signal(signal.SIGTERM)
            proc.wait(60)
            if pg is not None:
                pg.remove()
        verdicts = check(tmp, results, text_of, deadline)
    lat = [r["seconds"] for r in results.values()]
    server = [
        r["body"]["finished_at"] - r["body"]["created_at"] for r in results.values() if r["body"].get("finished_at")
    ]
    waited = [r["positions"] for r in results.values() if r["positions"]]
    late = sum(bool(r["body"].get("late")) for r in results.values())
    slips = sum(text_of[s][1] for s in results)
    print(
        f"{args.roster} students, each their own 'rp' variant (exercise make: {make_s:.0f} s), {slips} with a slip; "
        f"window {args.window:g} s, deadline at {1 - LATE_SHARE:.0%} of it, arrivals {args.arrivals}; "
        f"{args.concurrency} requests at a time; "
        f"{args.workers} workers, {os.cpu_count()} CPUs, load average {load0:.1f} at the start, {load1:.1f} at the end; "
        + ("PostgreSQL" if args.postgres else "SQLite")
    )
    print(
        "| students | lost | verdict != armdyn grade | late (marked wrong) | window start -> last verdict (s) | submit->verdict p50 / p95 (s) "
        "| server accept->verdict p50 / p95 (s) | waited in queue | largest position shown |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    print(
        f"| {len(results)}/{args.roster} | {len(errors)} | {len(verdicts['wrong'])} | {late} ({len(verdicts['late_wrong'])}) "
        f"| {wall:.0f} | {pct(lat, 50):.1f} / {pct(lat, 95):.1f} | {pct(server, 50):.1f} / {pct(server, 95):.1f} "
        f"| {len(waited)} | {max((max(p) for p in waited), default=0)} |"
    )
    for e in errors[:3]:
        print("  lost:", e)
    for sid in verdicts["wrong"][:3]:
        print("  verdict differs:", sid)
    for sid in verdicts["late_wrong"][:3]:
        print("  late mark wrong:", sid)
