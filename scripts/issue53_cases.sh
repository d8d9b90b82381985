#!/usr/bin/env bash
# The cases of issue 53 (real logs scored honestly), run by one binary: what it says of
# each, one block per case. Compare two builds side by side:
#
#   scripts/issue53_cases.sh target/release/onebeacon DIR
#   scripts/issue53_cases.sh /path/to/older/onebeacon DIR_OLD
#
# DIR receives the logs and outputs (made anew; it must not exist). Needs Python 3.
set -u
BIN=$(realpath "$1")
DIR=$2
HERE=$(cd "$(dirname "$0")/.." && pwd)
if [ -e "$DIR" ]; then echo "error: $DIR exists; give a new directory" >&2; exit 2; fi
mkdir -p "$DIR" && cd "$DIR" || exit 2
cp "$HERE"/data/plaza/plaza*.csv "$HERE"/data/plaza/plaza*.toml .

echo "== 1. plaza2, beacon 6's ranges 7.6 m long: what the replay says of it"
mkdir -p biased && cp plaza2* biased/
python3 - <<'EOF'
rows = open("plaza2_ranges.csv").read().splitlines()
out = [rows[0]] + [f"{t},{b},{float(r) + (7.6 if b == '6' else 0.0):.6f}" for t, b, r in (l.split(",") for l in rows[1:])]
open("biased/plaza2_ranges.csv", "w").write("\n".join(out) + "\n")
EOF
"$BIN" replay biased/plaza2.toml --out biased/out 2>&1 >/dev/null | grep -c "beacon 6" | sed 's/^/  warnings naming beacon 6: /'
"$BIN" replay biased/plaza2.toml --holdout 6 --out biased/h 2>/dev/null | sed -n '/^held out/,/^wrote/p' | grep -v '^wrote' | sed 's/^/  /'

echo "== 2. one beacon, an early false track: ekf-cal with the default range_scale_sigma"
python3 "$HERE"/scripts/lbl_burst.py lbl >/dev/null
printf '[[estimators]]\nname = "ekf-cal-default"\nkind = "range-ekf"\nestimate_bias = true\nestimate_range_scale = true\nestimate_turn_scale = true\n' > cal.toml
"$BIN" replay lbl/burst.toml --beacons 0 --estimators cal.toml --json --out lbl/one 2>/dev/null |
  python3 -c "import json,sys; e=json.load(sys.stdin)['estimators'][0]; print(f\"  {e['name']}: rmse {e['rmse_m']:.1f} m, max {e['max_error_m']:.1f} m\")"

echo "== 3. [noise] range_sigma_m = 3: the smoother and --estimators"
sed 's#^name = "plaza2"#name = "plaza2n"#' plaza2.toml > plaza2n.toml && printf '\n[noise]\nrange_sigma_m = 3.0\n' >> plaza2n.toml
printf '[[estimators]]\nname = "ekf"\nkind = "range-ekf"\n' > ekf.toml
for log in plaza2 plaza2n; do
  "$BIN" smooth $log.toml --json --out s-$log 2>/dev/null |
    python3 -c "import json,sys; d=json.load(sys.stdin); s=[e for e in d['estimators'] if e['name']=='smoother'][0]; print(f\"  smooth $log: rmse {s['rmse_m']:.4f} m\")"
  "$BIN" replay $log.toml --estimators ekf.toml --json --out e-$log 2>/dev/null |
    python3 -c "import json,sys; d=json.load(sys.stdin); print(f\"  replay $log --estimators (ekf): rmse {d['estimators'][0]['rmse_m']:.4f} m\")"
done

echo "== 4. plaza1 started from the ranges of the beacons run"
sed 's/^from = "ground_truth"/from = "ranges"\nranges_window_s = 20\nheading_deg = -118.1/' plaza1.toml > plaza1r.toml
for b in "" "--beacons 0,1,5" "--beacons 0"; do
  echo "  $b:"; "$BIN" replay plaza1r.toml $b --out r 2>&1 | grep -E "^start|^error" | sed 's/^/    /'
done

echo "== 5. tune a key the estimator does not use; intervals"
"$BIN" tune plaza1.toml --estimators ekf-cal --keys range_sigma_m,doppler_sigma_m_s --out t1 > t1.txt 2>&1
echo "  exit $?: $(tail -1 t1.txt)"
"$BIN" tune plaza1.toml --estimators ekf-cal --keys range_sigma_m,distance_sigma_frac --out t2 2>/dev/null | sed -n 2,4p | sed 's/^/  /'

echo "== 7. plaza2 as shipped: overconfidence named without ground truth"
"$BIN" replay plaza2.toml --out o 2>&1 >/dev/null | grep -c overconfident | sed 's/^/  lines: /'

echo "== 8. plaza2, its truth given sigma_m = 3"
python3 -c "
s=open('plaza2.toml').read(); print(s.replace('file = \"plaza2_ground_truth.csv\"', 'file = \"plaza2_ground_truth.csv\"\nsigma_m = 3.0', 1))" > plaza2s.toml
"$BIN" replay plaza2s.toml --json --out s 2>&1 >s.json | grep '^error' | sed 's/^/  /'
python3 -c "
import json,sys
t=open('s.json').read()
try:
    d=json.loads(t); e=[e for e in d['estimators'] if e['name']=='ekf-cal'][0]
    print(f\"  ekf-cal: rmse {e['rmse_m']:.3f} m, nees {e['nees_mean']:.2f}, floor {d['reference']['rmse_floor_m']:.2f} m\")
except Exception: print('  no summary')"

echo "== 11. stream of plaza2 (heading from the track): output lines per input line"
"$BIN" replay plaza2.toml --print-stream > items.jsonl
"$BIN" stream plaza2.toml < items.jsonl 2>/dev/null > out.jsonl
echo "  $(wc -l < items.jsonl) lines in, $(wc -l < out.jsonl) out"
"$BIN" replay plaza2.toml --print-stream --beacons 5 2>&1 | head -c 300 | head -1 | cut -c1-120 | sed 's/^/  --print-stream --beacons 5: /'
