"""Load test of ``armdyn serve``: C concurrent clients x K submissions of the exercise.

Starts ``python -m armdyn serve`` on 127.0.0.1 (a free port, a fresh SQLite file, W
grading workers), waits until it is ready, then runs C client threads, each posting
its K submissions one after the other (``POST /api/grade``, waiting for the verdict).
Every verdict is compared with ``armdyn.grade`` run here on the same text (step names
and statuses, first wrong step, torques); nothing may be lost.

Latency is accept -> verdict, measured two ways: by the client (request sent ->
response with the verdict) and by the server (``created_at`` -> ``finished_at`` of the
row). Two workloads:

  identical  the exercise's text every time (the target load): after the first
             grading, the server answers from its content-hash cache
  distinct   a unique comment line in each text (no cache): every submission is
             graded; latency is then queueing behind C*K gradings on W workers

    python benchmarks/bench_serve.py                                # both, 50 x 10, 2 workers
    python benchmarks/bench_serve.py --mode distinct --clients 50 --per-client 2
    python benchmarks/bench_serve.py --mode distinct --clients 20 --per-client 5 \
        --postgres --restart-db-at 20        # PostgreSQL, stopped for 3 s once mid-run

``--postgres`` starts a throwaway PostgreSQL cluster (Debian's binaries, a Unix socket in
a temporary folder, as .ci/run does); ``--restart-db-at S`` stops it S seconds into the
run and starts it again 3 s later: every submission must still get its verdict.

``--roster N`` is the deadline rush instead (``serve_rush.py``): N students, each with
their own variant and personal link, hand in around ``--deadline`` within ``--window``
seconds (600 for the reported run; less for a quick one), ``--concurrency`` requests at a
time; it reports lost submissions, verdicts that differ from ``armdyn.grade``, late marks
against the deadline, latencies and the queue positions students were shown.

    python benchmarks/bench_serve.py --roster 200 --window 600 [--postgres]

Not a test (pytest does not collect it); the numbers depend on the machine's load.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
EXERCISE = ROOT / "examples" / "grading" / "rp-arm-exercise.md"


def pct(values: list[float], p: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, max(0, round(p / 100 * (len(s) - 1))))]


def post(base: str, text: str) -> tuple[int, dict, float]:
    """Submit, wait for the verdict (POST waits up to 120 s, then poll GET); (status, body, seconds)."""
    req = urllib.request.Request(
        f"{base}/api/grade?wait=120", data=text.encode(), method="POST", headers={"content-type": "text/markdown"}
    )
    t0 = time.perf_counter()
    status, body = _send(req, 300)
    poll = f"{base}/api/submissions/{body['id']}?t={body['token']}"
    for _ in range(3600):  # bounded: at most an hour of polling
        if body["status"] in ("done", "failed"):
            break
        time.sleep(0.5)
        status, body = _send(poll, 60)
    return status, body, time.perf_counter() - t0


def _send(req, timeout: float, tries: int = 30) -> tuple[int, dict]:
    """(status, JSON body); a 503 (the database restarting, a full queue) is sent again
    after its Retry-After, as a browser or a script should, at most ``tries`` times."""
    for _ in range(tries - 1):
        try:
            with urllib.request.urlopen(req, timeout=timeout) as r:
                return r.status, json.loads(r.read())
        except urllib.error.HTTPError as err:
            if err.code != 503:
                raise
            time.sleep(float(err.headers.get("Retry-After") or 2))
    with urllib.request.urlopen(req, timeout=timeout) as r:
        return r.status, json.loads(r.read())


class Postgres:
    """A throwaway cluster on a Unix socket (as .ci/run starts one); ``restart`` stops it
    for ``outage`` seconds."""

    def __init__(self):
        bins = sorted(Path("/usr/lib/postgresql").glob("*/bin/initdb"))
        if not bins:
            raise SystemExit("--postgres: no PostgreSQL found (apt-get install postgresql)")
        # a folder of its own under /tmp: the postgres user cannot enter the benchmark's
        self.bin, self.dir = bins[-1].parent, Path(tempfile.mkdtemp(prefix="armdyn-bench-pg-"))
        self.as_pg = ["runuser", "-u", "postgres", "--"] if os.geteuid() == 0 else []
        if self.as_pg:
            shutil.chown(self.dir, "postgres")
        self._pg("initdb", "-D", str(self.dir / "data"), "-A", "trust", "-U", "postgres")
        self.start()
        self._pg("psql", "-h", str(self.dir), "-p", "55433", "-U", "postgres", "-q", "-c", "CREATE DATABASE bench")
        self.url = f"postgresql://postgres@/bench?host={self.dir}&port=55433"

    def _pg(self, tool: str, *args: str) -> None:
        subprocess.run([*self.as_pg, str(self.bin / tool), *args], check=True, capture_output=True, timeout=120)

    def start(self) -> None:
        opts = f"-k {self.dir} -p 55433 -c listen_addresses=''"
        self._pg("pg_ctl", "-D", str(self.dir / "data"), "-l", str(self.dir / "log"), "-w", "-o", opts, "start")

    def stop(self) -> None:
        self._pg("pg_ctl", "-D", str(self.dir / "data"), "-m", "fast", "-w", "stop")

    def remove(self) -> None:
        self.stop()
        shutil.rmtree(self.dir, ignore_errors=True)

    def restart(self, outage: float = 3.0) -> None:
        self.stop()
        time.sleep(outage)
        self.start()


def start(workers: int, tmp: str, db: str | None = None) -> tuple[subprocess.Popen, str]:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "armdyn",
            "serve",
            "--port",
            str(port),
            "--workers",
            str(workers),
            "--db",
            db or f"sqlite:///{tmp}/bench.db",
        ],
        env=env,
    )
    base = f"http://127.0.0.1:{port}"
    for _ in range(600):
        try:
            with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
                if r.status == 200:
                    return proc, base
        except OSError:
            pass
        time.sleep(0.2)
    proc.kill()
    raise SystemExit("the server did not become ready")


def run(base: str, mode: str, clients: int, per_client: int, expected: dict) -> dict:
    text = EXERCISE.read_text(encoding="utf-8")
    results, errors, lock = [], [], threading.Lock()

    def client(c: int):
        for k in range(per_client):
            body_text = text if mode == "identical" else f"{text}\n<!-- {mode} client {c} submission {k} -->\n"
            try:
                status, body, seconds = post(base, body_text)
            except Exception as err:  # noqa: BLE001 - counted as lost
                with lock:
                    errors.append(f"client {c} #{k}: {err}")
                continue
            with lock:
                results.append((status, body, seconds))

    t0 = time.perf_counter()
    threads = [threading.Thread(target=client, args=(c,)) for c in range(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall = time.perf_counter() - t0
    wrong = [
        b["id"]
        for s, b, _ in results
        if s != 200
        or b["status"] != "done"
        or b.get("first_wrong") != expected["first_wrong"]
        or b.get("tau_correct") != expected["tau_correct"]
        or [(x["name"], x["status"]) for x in b.get("steps", [])] != expected["steps"]
    ]
    client_lat = [sec for _, _, sec in results]
    server_lat = [b["finished_at"] - b["created_at"] for _, b, _ in results if b.get("finished_at")]
    grading = [b["finished_at"] - b["started_at"] for _, b, _ in results if not b["cached"] and b.get("started_at")]
    return {
        "mode": mode,
        "n": clients * per_client,
        "answered": len(results),
        "lost": len(errors),
        "wrong": len(wrong),
        "cached": sum(bool(b["cached"]) for _, b, _ in results),
        "wall": wall,
        "client_p50": pct(client_lat, 50),
        "client_p95": pct(client_lat, 95),
        "server_p50": pct(server_lat, 50),
        "server_p95": pct(server_lat, 95),
        "grading_p50": pct(grading, 50) if grading else float("nan"),
        "errors": errors[:3],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mode", choices=["identical", "distinct", "both"], default="both")
    ap.add_argument("--clients", type=int, default=50)
    ap.add_argument("--per-client", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--postgres", action="store_true", help="store in a throwaway PostgreSQL cluster")
    ap.add_argument("--restart-db-at", type=float, metavar="S", help="stop PostgreSQL S s into a run, for 3 s")
    ap.add_argument("--roster", type=int, metavar="N", help="the deadline rush: N students, personal links, variants")
    ap.add_argument("--window", type=float, default=600.0, help="--roster: seconds the class hands in over")
    ap.add_argument("--concurrency", type=int, default=32, help="--roster: requests open at a time")
    ap.add_argument(
        "--arrivals",
        choices=["uniform", "rush"],
        default="rush",
        help="--roster: hand-in times spread evenly, or densest at the deadline (Beta(5, 2) over the window)",
    )
    ap.add_argument("--seed", type=int, default=2026, help="--roster: the variants' and the hand-in times' seed")
    args = ap.parse_args()
    if args.roster is not None:
        from serve_rush import run_rush

        return run_rush(args, Postgres)
    if args.restart_db_at is not None and not args.postgres:
        ap.error("--restart-db-at needs --postgres")
    from armdyn.grading import grade
    from armdyn.grading.reader import read_markdown

    report = json.loads(grade(read_markdown("submission.md", EXERCISE.read_text(encoding="utf-8"))).to_json())
    expected = {
        "first_wrong": report["first_wrong"],
        "tau_correct": report["tau_correct"],
        "steps": [(s["name"], s["status"]) for s in report["steps"]],
    }
    modes = ["identical", "distinct"] if args.mode == "both" else [args.mode]
    rows = []
    with tempfile.TemporaryDirectory(prefix="armdyn-bench-serve-") as tmp:
        for mode in modes:
            os.makedirs(f"{tmp}/{mode}")
            pg = Postgres() if args.postgres else None
            proc, base = start(args.workers, f"{tmp}/{mode}", pg.url if pg else None)
            restart = None
            if pg is not None and args.restart_db_at is not None:
                restart = threading.Timer(args.restart_db_at, pg.restart)
                restart.start()
            try:
                rows.append(run(base, mode, args.clients, args.per_client, expected))
            finally:
                if restart is not None:
                    restart.join()
                proc.send_signal(signal.SIGTERM)
                proc.wait(60)
                if pg is not None:
                    pg.remove()
    print(
        f"{args.clients} clients x {args.per_client} submissions of the exercise, {args.workers} workers, "
        f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}, "
        + ("PostgreSQL" if args.postgres else "SQLite")
        + (f", database stopped for 3 s at {args.restart_db_at:g} s" if args.restart_db_at is not None else "")
    )
    print(
        "| workload | submissions | lost | verdict != armdyn grade | from cache | wall (s) | "
        "client p50 / p95 (s) | server accept->verdict p50 / p95 (s) | one grading p50 (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['mode']} | {r['answered']}/{r['n']} | {r['lost']} | {r['wrong']} | {r['cached']} | "
            f"{r['wall']:.1f} | {r['client_p50']:.2f} / {r['client_p95']:.2f} | "
            f"{r['server_p50']:.2f} / {r['server_p95']:.2f} | {r['grading_p50']:.2f} |"
        )
        for e in r["errors"]:
            print("  lost:", e)


if __name__ == "__main__":
    main()
