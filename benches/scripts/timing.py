"""What the comparison scripts beside it share: `least(f, repeat)`, the least wall time of
`repeat` calls of `f` and the last call's result (scripts run as `python
benches/scripts/X.py` import it from their own folder)."""
import time


def least(f, repeat):
    best, out = float("inf"), None
    for _ in range(repeat):
        s = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - s)
    return best, out
