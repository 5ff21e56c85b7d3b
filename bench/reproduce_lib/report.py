"""bench/reproduce_lib/report.py — number formatting and log-log
interpolation for the tables of bench/reproduce (the table and summary
writers are in bench/reproduce's main phases)."""
import math


def interp_loglog(s, t):
    """log-log interpolation of error at time t on a sorted [(time, err)] curve; None outside."""
    s = sorted(s)
    if s and abs(t - s[0][0]) < 1e-9 * max(1, t):
        return s[0][1]
    if s and abs(t - s[-1][0]) < 1e-9 * max(1, t):
        return s[-1][1]
    for (xa, ya), (xb, yb) in zip(s, s[1:]):
        if xa <= t <= xb and xa > 0 and ya > 0 and yb > 0:
            if xb == xa:
                return ya
            u = (math.log(t) - math.log(xa)) / (math.log(xb) - math.log(xa))
            return math.exp(math.log(ya) + u * (math.log(yb) - math.log(ya)))
    return None


def fmt(v, p=3):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    if v == 0:
        return "0"
    if abs(v) >= 1000 or abs(v) < 1e-3:
        return f"{v:.{p - 1}e}"
    return f"{v:.{p}g}"
