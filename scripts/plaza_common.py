"""What the plaza scripts share: reading a CSV file and the ground truth between its rows.
Only the standard library is used."""
import bisect, csv, os

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "plaza")

def rows(path):
    """The rows of a CSV file as dictionaries."""
    with open(path) as f:
        return list(csv.DictReader(f))

def truth_at(truth):
    """A function of time giving the (x, y) of the ground-truth rows `truth`, linearly
    interpolated (held at the ends)."""
    tt = [float(r["t_s"]) for r in truth]
    def at(t):
        i = min(max(bisect.bisect_left(tt, t), 1), len(tt) - 1)
        a, b = truth[i - 1], truth[i]
        w = min(max((t - tt[i - 1]) / (tt[i] - tt[i - 1]), 0.0), 1.0) if tt[i] > tt[i - 1] else 0.0
        return (float(a["x_m"]) + w * (float(b["x_m"]) - float(a["x_m"])),
                float(a["y_m"]) + w * (float(b["y_m"]) - float(a["y_m"])))
    return at
