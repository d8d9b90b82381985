"""docs/reproductions/receiver.md's tables: the receiver chain on simulated pings
(crates/onebeacon-sim/examples/dsp_trials.rs)."""

import functools
import json
import subprocess
import sys

from .common import ROOT, header


@functools.cache
def dsp_trials(quick):
    """The JSON of the receiver chain's trials (crates/onebeacon-sim/examples/dsp_trials.rs),
    run once per script run."""
    args = ["cargo", "run", "--release", "--quiet", "-p", "onebeacon-sim", "--example", "dsp_trials", "--"]
    done = subprocess.run([*args, *(["--quick"] if quick else [])], cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"reproduce: the dsp_trials example failed ({done.returncode}): {done.stderr.strip()}")
    return json.loads(done.stdout)


def receiver_pings(quick):
    """docs/reproductions/receiver.md: the rypkema chirp at 20 dB through the
    5-element array, 68th percentiles of the errors over the pings."""
    rows = header("channel", "pings", "range error, m", "azimuth error, deg", "azimuth error / its CRB sigma",
                  "direction error, deg")
    for p in dsp_trials(quick)["pings"]:
        e = p["errors"]
        rows.append(f"| {p['channel']} | {e['pings']} | {e['range_m_68']:.3f} | {e['azimuth_deg_68']:.2f} "
                    f"| {e['azimuth_over_crb_68']:.2f} | {e['direction_deg_68']:.2f} |")
    return rows


def receiver_modes(quick):
    """docs/reproductions/receiver.md: the share of pings whose command mode
    the bank identifies, searching the whole capture or gated around a prediction."""
    rows = header("2E/N0 per element", "pings", "whole capture", "gated +-15 m", "gated +-5 m")
    for m in dsp_trials(quick)["modes"]:
        shares = " | ".join(f"{100 * m[k]:.1f} %" for k in ("whole", "gate_15", "gate_5"))
        rows.append(f"| {m['snr_db']:g} dB | {m['pings']} | {shares} |")
    return rows


def receiver_garin(quick):
    """docs/reproductions/receiver.md: garin2024's Doppler speed (eq. 9 and the
    periodogram) on its pure tone and its range from frame synchronisation (eq. 12)."""
    g = dsp_trials(quick)["garin"]
    return header("at 2E/N0 = 20 dB", "frames", "error") + [
        f"| Doppler speed, periodogram (ML), RMSE | {g['tone_frames']} | {g['ml_rmse_m_s']:.4f} m/s "
        f"({g['ml_rmse_m_s'] / g['bound_m_s']:.2f} x bound) |",
        f"| Doppler speed, eq. 9 (one lag), RMSE | {g['tone_frames']} | {g['eq9_rmse_m_s']:.4f} m/s "
        f"({g['eq9_rmse_m_s'] / g['bound_m_s']:.2f} x bound) |",
        f"| Doppler speed, the bound (CRLB) | | {g['bound_m_s']:.4f} m/s |",
        f"| range, frame synchronisation (eq. 12), RMS / 68 % | {g['sync_frames']} | {g['sync_rms_m']:.4f} / "
        f"{g['sync_68_m']:.4f} m |",
    ]


def detection_rows(rows_in, first):
    """Rows of a detection-statistic table: the capture, how many, `first(row)` (more
    cells), the statistic's quantiles and how many reached the threshold."""
    rows = []
    for r in rows_in:
        s = r["statistic"]
        label = "noise only" if r["snr_db"] is None else f"{r['snr_db']:g} dB"
        quantiles = " | ".join(f"{s[k]:.4f}" for k in ("p01", "p05", "median", "p99", "p999", "max"))
        rows.append(f"| {label} | {s['n']} | {first(r)}{quantiles} | {s['reaching_threshold']} |")
    return rows


def receiver_chirp_detection(quick):
    """docs/reproductions/receiver.md: the chirp's detection statistic on
    noise-only captures and on pings at falling 2E/N0 per element."""
    t = dsp_trials(quick)["chirp_detection"]
    rows = header("capture", "count", "1 %", "5 %", "median", "99 %", "99.9 %", "max",
                  f"at or over {t['threshold']:.4f}")
    return rows + detection_rows(t["rows"], lambda r: "")


def receiver_frame_detection(quick):
    """docs/reproductions/receiver.md: the detection statistic of garin2024's
    frame synchronisation, on noise-only captures and on frames at falling 2E/N0 (whole
    frame, per element), with the frames synchronised within 1 m and the peak over the
    mean of the output (median) for comparison."""
    t = dsp_trials(quick)["frame_detection"]
    rows = header("capture", "count", "synchronised within 1 m", "peak / mean, median", "1 %", "5 %", "median",
                  "99 %", "99.9 %", "max", f"at or over {t['threshold']:.4f}")
    def first(r):
        synchronised = "-" if r["snr_db"] is None else r["synchronised"]
        return f"{synchronised} | {r['peak_over_mean']['median']:.1f} | "

    return rows + detection_rows(t["rows"], first)


# the tables of this module by the name that marks them in docs/
TABLES = {
    "receiver-pings": receiver_pings,
    "receiver-modes": receiver_modes,
    "receiver-garin": receiver_garin,
    "receiver-chirp-detection": receiver_chirp_detection,
    "receiver-frame-detection": receiver_frame_detection,
}
