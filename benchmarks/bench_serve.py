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

Not a test (pytest does not collect it); the numbers depend on the machine's load.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
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
    with urllib.request.urlopen(req, timeout=300) as r:
        status, body = r.status, json.loads(r.read())
    poll = f"{base}/api/submissions/{body['id']}?t={body['token']}"
    for _ in range(3600):  # bounded: at most an hour of polling
        if body["status"] in ("done", "failed"):
            break
        time.sleep(0.5)
        with urllib.request.urlopen(poll, timeout=60) as r:
            status, body = r.status, json.loads(r.read())
    return status, body, time.perf_counter() - t0


def start(workers: int, tmp: str) -> tuple[subprocess.Popen, str]:
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
            f"sqlite:///{tmp}/bench.db",
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
    args = ap.parse_args()
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
            proc, base = start(args.workers, f"{tmp}/{mode}")
            try:
                rows.append(run(base, mode, args.clients, args.per_client, expected))
            finally:
                proc.send_signal(signal.SIGTERM)
                proc.wait(60)
    print(
        f"{args.clients} clients x {args.per_client} submissions of the exercise, {args.workers} workers, "
        f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}"
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
