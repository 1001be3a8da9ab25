

# ------------------------------------------------------------------ F4: a wrong step's message is bounded

#: 95 bytes of LaTeX whose difference from the right tau_1 expands into 230 230 terms
BLOW_UP = r"\tau_1 = (l_1\theta_1 + d_2 + \dot\theta_1 + \ddot\theta_1 + m_1 + m_2 + g)^{20}"


def test_a_difference_that_expands_hugely_is_graded_in_seconds(tmp_path):
    """Expanding or factoring the difference for the message took > 10 min and 730 MB;
    now the step is wrong (no 20th power of that sum is rp-arm's tau_1: at the origin
    with l1 = 1 and the rest 0 the sum is 0, not m1 g l1... checked numerically by the
    grader) and the message says the difference was not simplified."""
    assert len(BLOW_UP) == 95
    sub = tmp_path / "pow.md"
    sub.write_text(f"---\nrobot: rp-arm\n---\n$${BLOW_UP}$$\n")
    t0 = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-m", "armdyn", "grade", str(sub), "--json", "--html", str(tmp_path / "pow.html")],
        capture_output=True,
        text=True,
        timeout=60,
        env=PYTHON_ENV,
    )
    seconds = time.monotonic() - t0
    assert done.returncode == 1, done.stderr  # graded: a step wrong
    step = json.loads(done.stdout)["steps"][0]
    assert step["status"] == "wrong" and "not simplified" in step["message"]
    assert seconds < 30, seconds
    assert (tmp_path / "pow.html").stat().st_size > 0


def test_the_expansion_estimate_bounds_what_sympy_makes():
    """expanded_terms against SymPy's own expansion (small cases) and the multinomial
    count C(n + k - 1, k - 1) by hand (large ones)."""
    import math

    import sympy as sp

    from armdyn.grading.explain import EXPAND_LIMIT, affordable, expanded_terms

    a, b, c, d, x = sp.symbols("a b c d x")
    for e in [(a + b + c) ** 3, (a + b) * (c + d) ** 2, sp.sin(a + b + c), sp.cos(x) ** 4 * (a + b), 1 / (a + b) ** 3]:
        real = len(sp.Add.make_args(sp.expand(sp.expand_trig(e))))
        assert real <= expanded_terms(e) <= EXPAND_LIMIT, e
    seven = sum(sp.symbols("s1:8"))
    assert math.comb(20 + 7 - 1, 7 - 1) == 230230 > EXPAND_LIMIT
    assert expanded_terms(seven**20) == EXPAND_LIMIT + 1 and not affordable(seven**20)
    assert expanded_terms(sp.exp(seven**20) + a) == EXPAND_LIMIT + 1  # inside a function too
    assert affordable((a + b) ** 2 * sp.sin(x + a))
