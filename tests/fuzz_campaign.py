"""A long fuzz campaign, outside CI (pytest collects none of the fuzz_*.py files); the kinds
live in fuzz_models.py, fuzz_markup.py and fuzz_io.py, this file drives them:

    PYTHONPATH=python python3 tests/fuzz_campaign.py --count 100000          # each kind
    PYTHONPATH=python python3 tests/fuzz_campaign.py --kinds arrays --count 100000
    PYTHONPATH=python python3 tests/fuzz_campaign.py --minutes 20            # stop early

Kinds of input (each from a fixed seed, so a finding can be replayed):

* ``yaml``:   the bundled frame-based YAML models (rp-arm, planar-2r, panda... the small
  ones), mutated structurally (a value replaced by a hostile one, a key dropped, an item
  duplicated) or as text (cut, spliced, bytes flipped), then loaded;
* ``dh``:     the same for the DH-table models (planar-3r, scara, puma560, ur5, ...);
* ``urdf``:   a hand-made URDF and the bundled iiwa14, mutated as XML (attributes set to
  hostile numbers, elements dropped or duplicated, names swapped) or as text;
* ``arrays``: random arrays (shapes, dtypes, NaN/inf/huge values, non-contiguous, object
  and complex arrays, odd ``threads``/``link`` values) into every numeric function of a
  few compiled robots;
* ``html``:   payloads into HTML (run it with ``--kinds html``): random strings of script
  and markup fragments (tests/html_payloads.py) as a student's LaTeX label, as raw
  MathML for the sanitizer, as symbol names in the MathML printer and as a model's
  robot/link/joint names in ``Robot._repr_html_`` and a page; the output must pass an
  HTML tokenizer's check independent of the sanitizer (no foreign element, no on*
  attribute, no link or style attribute, no ``javascript:``), parse as XML with only
  whitelisted MathML, and the sanitizer must be idempotent on it.
* ``names``:  names into codegen: hostile robot and joint names (comment and docstring
  ends, trigraphs, NFKC look-alikes) through the header printer and the identifier table
  (no compiling: the header must parse as one docstring and hold no comment end; the
  identifiers must be ASCII, unique, no keyword);
* ``aliases``: alias bombs in every field of planar-2r (and deep nesting, huge integers);
* ``serve``:  hostile sizes and timings against ``armdyn serve`` on 127.0.0.1 (a server
  per worker process): bodies of 0 B to 3 MB, NUL and invalid UTF-8, odd content types,
  query values and submission ids, and raw connections that stop mid-head, trickle,
  lie about their length or send a 200 kB head. Each answer must be below 500 (503
  with Retry-After only for previews) and ``/api/health`` 200 afterwards (the database:
  a fresh SQLite file, or ``ARMDYN_FUZZ_SERVE_DB``, e.g. a throwaway PostgreSQL). Use a small
  ``--count`` (each input is a request; ~1000 take a minute or two);
* ``towers``: power towers (powers, exponentials, products of huge numbers) in model
  expressions. For these three anything but a result or a ``ModelError`` within 5 s is a
  finding;
* ``codemodels``: model files that try to run code (run it with ``--kinds codemodels``):
  xacro ``${...}`` payloads (the ``vars()``/``type()`` bypass of xacro's filter),
  ``.xacro`` files, includes and ``package://``/``file://`` URIs in URDF, YAML tags that
  construct Python objects, Python in DH and frame expressions; loaded untrusted, each
  must end in a result or a ``ModelError`` within 5 s and leave no marker file;
* ``classes``: hostile class folders for ``armdyn grade DIR``'s discovery (spoofed
  ``student:``/``variant:``, colliding report names, models named by paths out of the
  folder, symbolic links to files outside, to /dev/zero and FIFOs): every student is
  the file's name, no link is followed, no two reports share a name, every model is
  bundled or a regular file in the folder, and no payload runs.

A model that loads is bound to its defaults and, when numeric, compiled and evaluated
once. Each input must end in a result or an expected error (``ModelError``,
``ValueError``, ``TypeError``, ``UnboundParameterError``) within ``--timeout`` seconds.
Everything else is a finding: another exception, a timeout (hang), a worker that dies
(crash), or a Rust panic message on stderr. Workers run chunks of inputs in separate
processes; stderr of each is captured at the file-descriptor level and searched for
"panicked". Prints one line of counts per kind and exits 1 if anything was found.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
import warnings

from fuzz_io import IO_KINDS, PREPARE, run_serve
from fuzz_markup import RUNNERS, SECURITY_KINDS
from fuzz_models import CHUNK, DH_SEEDS, EXPECTED, YAML_SEEDS, _fill_robots_cache, run_arrays, run_urdf, run_yaml

RUNNERS.update(SECURITY_KINDS)
RUNNERS["serve"] = run_serve
RUNNERS.update(IO_KINDS)

# ------------------------------------------------------------------ worker / driver


def worker(kind: str, first: int, count: int, timeout: float) -> dict:
    warnings.simplefilter("ignore")
    sys.setrecursionlimit(10_000)
    counts = {"inputs": 0, "loaded_or_ok": 0, "expected_error": 0, "unexpected": 0, "timeout": 0}
    findings = []

    def expired(*_):
        raise TimeoutError

    signal.signal(signal.SIGALRM, expired)
    # imports before the first timer: under load (nice 19 behind other jobs) importing
    # SymPy and armdyn took > 20 s and was counted as the chunk's first input timing out
    import armdyn.io.urdf  # noqa: F401
    import armdyn.io.yaml  # noqa: F401
    import armdyn.numeric  # noqa: F401

    if kind == "arrays":  # likewise the robots it feeds (the first input built them)
        _fill_robots_cache()
    if kind in PREPARE:
        PREPARE[kind]()
    for seed in range(first, first + count):
        rng = random.Random(seed)
        counts["inputs"] += 1
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            if kind == "yaml":
                run_yaml(seed, rng, YAML_SEEDS)
            elif kind == "dh":
                run_yaml(seed, rng, DH_SEEDS)
            elif kind == "urdf":
                run_urdf(seed, rng)
            elif kind in RUNNERS:
                RUNNERS[kind](seed, rng)
            else:
                run_arrays(seed, rng)
            counts["loaded_or_ok"] += 1
        except TimeoutError:
            counts["timeout"] += 1
            findings.append({"seed": seed, "kind": kind, "what": f"no result after {timeout} s"})
        except Exception as err:  # noqa: BLE001 - classified here
            name = type(err).__name__
            message = str(err)
            if name in EXPECTED and "internal error" not in message and "\n" not in message:
                counts["expected_error"] += 1
            else:
                counts["unexpected"] += 1
                findings.append({"seed": seed, "kind": kind, "what": f"{name}: {message[:300]}"})
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
    return {"counts": counts, "findings": findings[:20]}


def drive(kinds: list[str], count: int, timeout: float, minutes: float | None, jobs: int, first_seed: int = 0) -> int:
    """Run seeds ``first_seed`` .. ``first_seed + count - 1`` of each kind (``--first N --count 1``
    replays seed N)."""
    total = {}
    found = []
    start = time.monotonic()
    for kind in kinds:
        deadline = time.monotonic() + minutes * 60 if minutes else None
        total[kind] = {
            "inputs": 0,
            "loaded_or_ok": 0,
            "expected_error": 0,
            "unexpected": 0,
            "timeout": 0,
            "crash": 0,
            "panic_on_stderr": 0,
        }
        chunks = [
            (first, min(CHUNK, first_seed + count - first)) for first in range(first_seed, first_seed + count, CHUNK)
        ]
        running = []
        t_kind = time.monotonic()
        while chunks or running:
            while chunks and len(running) < jobs and not (deadline and time.monotonic() > deadline):
                first, n = chunks.pop(0)
                err = tempfile.TemporaryFile()
                cmd = [
                    sys.executable,
                    __file__,
                    "--worker",
                    kind,
                    "--first",
                    str(first),
                    "--count",
                    str(n),
                    "--timeout",
                    str(timeout),
                ]
                running.append((subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, text=True), err, first))
            if not running:
                break
            proc, err, first = running.pop(0)
            out, _ = proc.communicate()
            err.seek(0)
            stderr = err.read().decode("utf-8", "replace")
            t = total[kind]
            if proc.returncode != 0:
                t["crash"] += 1
                found.append({"kind": kind, "chunk": first, "what": f"worker exit {proc.returncode}: {stderr[-300:]}"})
                continue
            result = json.loads(out)
            for k, v in result["counts"].items():
                t[k] += v
            found += result["findings"]
            if re.search(r"panicked", stderr):
                t["panic_on_stderr"] += 1
                found.append({"kind": kind, "chunk": first, "what": stderr[-300:]})
        seconds = time.monotonic() - t_kind
        t = total[kind]
        print(
            f"{kind:>6}: {t['inputs']} inputs in {seconds:.0f} s: {t['loaded_or_ok']} loaded/evaluated, "
            f"{t['expected_error']} clear errors, {t['unexpected']} unexpected exceptions, {t['timeout']} "
            f"timeouts (>{timeout} s), {t['crash']} crashed workers, {t['panic_on_stderr']} chunks with a "
            f"panic message on stderr",
            flush=True,
        )
        for f in [f for f in found if f["kind"] == kind][:30]:
            print("finding:", json.dumps(f), flush=True)
    print(f"total {sum(t['inputs'] for t in total.values())} inputs in {time.monotonic() - start:.0f} s")
    bad = sum(t["unexpected"] + t["timeout"] + t["crash"] + t["panic_on_stderr"] for t in total.values())
    return 1 if bad else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kinds", default="yaml,dh,urdf,arrays")
    ap.add_argument("--count", type=int, default=100_000, help="inputs per kind")
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds one input may take")
    ap.add_argument("--minutes", type=float, help="per kind: stop starting new chunks after this long")
    ap.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 1)))
    ap.add_argument("--worker")
    ap.add_argument("--first", type=int, default=0)
    args = ap.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.first, args.count, args.timeout)))
        return 0
    if args.count < 1:
        ap.error("--count must be at least 1")
    return drive(args.kinds.split(","), args.count, args.timeout, args.minutes, args.jobs, args.first)


if __name__ == "__main__":
    sys.exit(main())
