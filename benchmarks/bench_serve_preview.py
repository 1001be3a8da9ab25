"""``GET /api/health`` while one client floods ``POST /api/preview`` (bounded, 127.0.0.1).

Starts ``armdyn serve`` (bench_serve.start: a free port of 127.0.0.1, a fresh SQLite
file), then sends ``--clients`` concurrent previews of ``--size`` bytes of display math
(each client one request) and, meanwhile, ``GET /api/health`` once every 0.2 s. Prints
the previews' statuses (200 or 503 with Retry-After: the server keeps a small queue
of previews and refuses the rest) and the health latencies; the target is under 1 s.

    python benchmarks/bench_serve_preview.py                     # 150 clients x 200 kB
    python benchmarks/bench_serve_preview.py --clients 50 --size 50000

Not a test (pytest does not collect it); the numbers depend on the machine's load.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_serve import pct, start  # noqa: E402


def preview(base: str, body: bytes) -> tuple[int, str | None]:
    req = urllib.request.Request(
        f"{base}/api/preview?exercise=rp-arm", data=body, method="POST", headers={"content-type": "text/markdown"}
    )
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            r.read()
            return r.status, None
    except urllib.error.HTTPError as err:
        return err.code, err.headers.get("retry-after")
    except OSError as err:
        return 0, type(err).__name__


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--clients", type=int, default=150)
    ap.add_argument("--size", type=int, default=200_000, help="bytes of each preview (default 200000)")
    args = ap.parse_args()
    clients = min(args.clients, 500)  # bounded whatever is asked
    line = "$$\\tau_1 = m_1 \\ddot{q}_1 + m_1 g \\cos(q_1)$$\n\n"
    body = (line * (args.size // len(line) + 1))[: args.size].encode()
    with tempfile.TemporaryDirectory() as tmp:
        proc, base = start(1, tmp)
        try:
            latencies, when, stop = [], [], threading.Event()
            started = time.perf_counter()

            def watch():
                while not stop.is_set() and len(latencies) < 3000:
                    t0 = time.perf_counter()
                    try:
                        with urllib.request.urlopen(base + "/api/health", timeout=120) as r:
                            r.read()
                    except OSError:
                        pass
                    latencies.append(time.perf_counter() - t0)
                    when.append(t0 - started)
                    stop.wait(0.2)

            watcher = threading.Thread(target=watch)
            watcher.start()
            t0 = time.perf_counter()
            with ThreadPoolExecutor(clients) as ex:
                results = list(ex.map(lambda _: preview(base, body), range(clients)))
            wall = time.perf_counter() - t0
            stop.set()
            watcher.join()
        finally:
            proc.send_signal(signal.SIGTERM)
            proc.wait(60)
    statuses = Counter(s for s, _ in results)
    retry = sorted({r for s, r in results if s == 503 and r})
    print(f"{clients} previews of {args.size} bytes in {wall:.1f} s: statuses {dict(statuses)}, Retry-After {retry}")
    print(
        f"GET /api/health during the load: {len(latencies)} requests, p50 {pct(latencies, 50):.3f} s, "
        f"p95 {pct(latencies, 95):.3f} s, max {max(latencies):.3f} s (target < 1 s)"
    )
    worst = sorted(zip(latencies, when), reverse=True)[:3]
    print("slowest health requests (seconds, sent at second): " + ", ".join(f"{a:.2f} at {b:.1f}" for a, b in worst))
    print(f"load average: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
