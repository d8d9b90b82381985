#!/usr/bin/env bash
# The careless and hostile cases of issues 27 (1-16) and 52 (17-33), one line each (what
# the command did):
# run it with an older binary and with this one to see a change. Usage:
#   scripts/hostile_cases.sh ONEBEACON WORKDIR   (WORKDIR must not exist; it is made)
# With a binary from before issue 27, case 5 allocates up to 16 GB for 8 s and case 7
# reads /dev/zero until the memory runs out (the kernel kills it); before issue 52,
# case 24 reads /dev/zero likewise (4 GB each): run that on a machine with room to
# spare. Cases 17-33 need python3; the whole script takes about 5 minutes.
set -u
[ $# -eq 2 ] || { echo "usage: $0 ONEBEACON WORKDIR" >&2; exit 2; }
[ -e "$2" ] && { echo "$2 exists: name a new directory" >&2; exit 2; }
B=$(realpath "$1"); W=$2; REPO=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$W"; cd "$W"
say() { printf '%s | %s\n' "$1" "$2"; }
line() { tr '\n' ' ' < "$1" | cut -c1-230; }
# 1 replay into the log's own directory
mkdir dl && cp $REPO/data/plaza/* dl/; n0=$(ls dl | wc -l)
$B replay dl/plaza1.toml --out dl > o1 2> e1; rc=$?; say "1 replay dl/plaza1.toml --out dl" "rc $rc; files of the log kept: $(ls dl | grep -c -v -e "^trajectory.csv$" -e "^summary.json$" -e "^rejected.csv$" -e "\.png$" -e "\.svg$")/$n0; $(line e1)"
# 2 a thesis in --out
mkdir u && echo x > u/thesis.tex
$B run garin2024 --out u > o2 2> e2; rc=$?; say "2 run garin2024 --out u (u/thesis.tex)" "rc $rc; thesis.tex $( [ -f u/thesis.tex ] && echo kept || echo DELETED); $(line e2)"
# 3 the working directory
mkdir w && echo x > w/notes.txt && (cd w && $B run garin2024 --out . > ../o3 2> ../e3; echo $? > ../rc3); say "3 (cd w; run garin2024 --out .)" "rc $(cat rc3); notes.txt $( [ -f w/notes.txt ] && echo kept || echo DELETED); $(line e3)"
# 4 a Slurm --out that holds code
mkdir stub && cat > stub/sbatch <<'S'
#!/usr/bin/env bash
array=""; for a in "$@"; do case "$a" in --array=*) array=${a#--array=0-};; esac; done
s=$(mktemp); cat > "$s"
if [ -n "$array" ]; then for i in $(seq 0 "$array"); do SLURM_ARRAY_TASK_ID=$i bash "$s" >/dev/null 2>&1; done; else bash "$s" >/dev/null 2>&1; fi
echo 7
S
chmod +x stub/sbatch
printf 'name = "s"\n[mission]\nduration_s = 60\n[sweep]\nt_com_s = [3.0]\n' > s.toml
$B mc s.toml --runs 2 --slurm 2 --out 'o$(touch PWNED)' > o4 2> e4; PATH=$PWD/stub:$PATH bash 'o$(touch PWNED)/campaign.sh' > o4b 2> e4b; rc=$?
say "4 mc --slurm 2 --out 'o\$(touch PWNED)'; bash campaign.sh (stub sbatch)" "rc $rc; PWNED $( [ -e PWNED ] && echo CREATED || echo 'not created'); result $( [ -f 'o$(touch PWNED)/result/mc.json' ] && echo 'in the right directory' || echo missing)"
# 5 5e7 particles on 2 threads
$B scenarios --show hoff2024 | sed 's/^particles = 500000 .*/particles = 50000000/; s/^duration_s = 3600 .*/duration_s = 60/' > h.toml
timeout 8 $B mc h.toml --runs 2 --threads 2 > o5 2> e5; rc=$?; say "5 mc (hoff2024, particles = 5e7) --runs 2 --threads 2" "rc $rc $( [ $rc = 124 ] && echo '(accepted, still allocating/running at 8 s)'); $(line e5)"
# (a latitude of 95 deg in a data row: tests/replay.rs, plaza_with_clock_times_and_latitudes...)
# 7 merge /dev/zero
timeout 60 $B mc merge /dev/zero > o7 2> e7; rc=$?; say "7 mc merge /dev/zero" "rc $rc; $(line e7)"
# 8 position_sigma_m = 1e308 (sousa, 30 s)
$B scenarios --show sousa | sed 's/^position_sigma_m = 1.0 .*/position_sigma_m = 1e308/; s/^duration_s = 7200.*/duration_s = 30/' > sig.toml
timeout 20 $B run sig.toml --out sig > o8 2> e8; rc=$?; say "8 run (sousa, initial.position_sigma_m = 1e308)" "rc $rc $( [ $rc = 124 ] && echo '(hung in the plotter, killed at 20 s)'); $(line e8 | tail -c 150)"
# 9 dt_s longer than the mission
printf 'name = "d"\n[mission]\nduration_s = 60\ndt_s = 100\n' > dt.toml
$B mc dt.toml --runs 1 --json > o9 2> e9; rc=$?; say "9 mc (mission.dt_s = 100 > duration_s = 60)" "rc $rc; $(line e9)"
# 10 speed 1e-300
printf 'name = "c"\n[mission]\nspeed_m_s = 1e-300\n' > sp.toml
$B mc sp.toml > o10 2> e10; rc=$?; say "10 mc (mission.speed_m_s = 1e-300)" "rc $rc; $(line e10 | cut -c1-200)"
# 11 --shard above the pairs
$B mc s.toml --runs 2 --shard 5/9 --out sh > o11 2> e11; rc=$?; say "11 mc --runs 2 --shard 5/9 (2 pairs)" "rc $rc; $(line e11)"
# 12 SIGKILL leftovers
mkdir k; $B mc garin2024 --runs 300 --out k/res > /dev/null 2>&1 & p=$!; sleep 1.5; kill -9 $p; wait $p 2>/dev/null
left=$(ls -a k | grep -c partial); $B run s.toml --out k/res > /dev/null 2>&1; say "12 SIGKILL during mc --out k/res, then run --out k/res" "left by the kill: $left; after the next run: $(ls -a k | grep -c partial)"
# 13 AUV 1e9 m deep in 5.3 m of water
$B scenarios --show rypkema-m1 | sed '0,/^depth_m = 2.5/s//depth_m = 1e9/' > deep.toml
timeout 20 $B fleet deep.toml --runs 1 --json > o13 2> e13; rc=$?; say "13 fleet (rypkema-m1, auvs[0].depth_m = 1e9)" "rc $rc; $(line e13)"
# 14 array elements at one point
printf '[array]\nkind = "custom"\nelements_m = [[0.1, 0, 0], [0.1, 0, 0], [0.1, 0, 0], [0.1, 0, 0]]\n' > arr.toml
$B dsp simulate --config arr.toml --out arr.wav > o14 2> e14; rc=$?; c=""; [ $rc = 0 ] && c=$($B dsp process arr.wav --config arr.toml --json 2>&1 | tr -d ' ' | grep -o '"consistent":[a-z]*')
say "14 dsp simulate/process (4 elements at one point)" "rc $rc $c; $(line e14)"
# 15 particles = u64::MAX
$B scenarios --show hoff2024 | sed 's/^particles = 500000 .*/particles = 18446744073709551615/' > pmax.toml
$B mc pmax.toml > o15 2> e15; rc=$?; say "15 mc (particles = 18446744073709551615)" "rc $rc; $(line e15)"
# 16 a DC offset alone
python3 - <<'P'
import struct
ch, n, fs = 5, 8000, 37500
data = struct.pack('<f', 0.3) * (ch*n)
hdr = b'RIFF' + struct.pack('<I', 36 + len(data)) + b'WAVE' + b'fmt ' + struct.pack('<IHHIIHH', 16, 3, ch, fs, fs*ch*4, ch*4, 32) + b'data' + struct.pack('<I', len(data))
open('dc.wav','wb').write(hdr+data)
P
$B dsp process dc.wav > o16 2> e16; rc=$?; say "16 dsp process dc.wav (0.3 on every channel, no ping)" "rc $rc; $(line o16)"

# ---- issue 52 ----
maxdev() { python3 - "$@" <<'P'
import json, math, sys
a = {}
for l in open(sys.argv[1]):
    d = json.loads(l); a[d['line']] = d
b = {}
for l in open(sys.argv[2]):
    d = json.loads(l); b[d['line']] = d
n = int(sys.argv[3]); worst = {}
for k, x in a.items():
    y = next((b[j] for j in range(n * k, n * (k - 1), -1) if j in b), None)
    if y is None: continue
    for ex, ey in zip(x['estimates'], y['estimates']):
        if ex['x_m'] is None or ey['x_m'] is None: continue
        worst[ex['name']] = max(worst.get(ex['name'], 0), math.hypot(ex['x_m'] - ey['x_m'], ex['y_m'] - ey['y_m']))
print(', '.join(f"{k} {v:.2f} m" for k, v in worst.items()))
P
}
printf 'name = "short"\n[mission]\nduration_s = 120.0\n[sweep]\nt_com_s = [3.0, 9.0]\n' > short.toml
# 17 mc merge over its own partials
for i in 0 1; do $B mc short.toml --runs 2 --shard $i/2 --out pp > /dev/null 2>&1; done
$B mc merge pp --out pp > o17 2> e17; rc=$?; say "17 mc merge pp --out pp (2 partials in pp)" "rc $rc; partials kept: $(ls pp | grep -c '^partial-')/2; $(line e17)"
# 18 replay --estimators t/estimators.toml --out t
mkdir p1 && cp $REPO/data/plaza/plaza1* p1/
$B tune p1/plaza1.toml --out t > /dev/null 2>&1; $B replay p1/plaza1.toml --estimators t/estimators.toml --out t > o18 2> e18; rc=$?
say "18 tune --out t; replay --estimators t/estimators.toml --out t" "rc $rc; t/estimators.toml $( [ -f t/estimators.toml ] && echo kept || echo DELETED); $(line e18)"
# 19 a file written into DIR during a long mc --out DIR
$B run short.toml --out k2 > /dev/null 2>&1
$B mc garin2024 --runs 100 --out k2 > o19 2> e19 & p=$!; sleep 2; echo mine > k2/notes.txt; wait $p; rc=$?
say "19 mc garin2024 --runs 100 --out k2; k2/notes.txt written 2 s in" "rc $rc; notes.txt $( [ -f k2/notes.txt ] && echo kept || echo DELETED); mc.json $( [ -f k2/mc.json ] && echo written || echo 'NOT written'); $(line e19 | tail -c 160)"
# 20 a stream on UNIX seconds against the configuration's t0_s = 0
$B scenarios --show hoff2024 | sed 's/^duration_s = 3600 .*/duration_s = 120/' > h120.toml
$B run h120.toml --messages --out hm > /dev/null 2>&1
python3 -c "
import json
for l in open('hm/asv.input.jsonl'):
    d = json.loads(l); d['t_s'] += 1.7e9; print(json.dumps(d))" > unix.jsonl
$B stream hm/asv.stream.toml < unix.jsonl > o20 2> e20; rc=$?
far=$(python3 -c "
import json
m = 0
for l in open('o20'):
    for e in json.loads(l).get('estimates') or []:
        if e.get('x_m') is not None: m = max(m, abs(e['x_m']), abs(e['y_m']))
print(f'{m:.3g}')")
say "20 stream (hoff2024's surface vehicle, t0_s = 0, times + 1.7e9 s)" "rc $rc; largest |x|, |y| of any estimate: $far m; screened lines: $(grep -c 'screened' e20)"
# 21 smooth with a beacon x100
mkdir p4 && cp $REPO/data/plaza/plaza1* p4/
python3 -c "
import csv
rows = list(csv.reader(open('p4/plaza1_beacons.csv')))
rows[1] = [rows[1][0], str(float(rows[1][1]) * 100), str(float(rows[1][2]) * 100)]
csv.writer(open('p4/plaza1_beacons.csv', 'w')).writerows(rows)"
$B smooth p4/plaza1.toml --out s21 > o21 2> e21; rc=$?
say "21 smooth plaza1 (beacon 0 x100)" "rc $rc; smoother RMSE $(awk '$1=="smoother" && $2+0==$2 {print $2}' o21) m; warnings: $(grep -c '^warning' e21); $(grep -o 'range_scale [-0-9.]*' o21 | head -1)"
# 22 the stream's memory budget
sed 's/^particles = 500000/particles = 50000000/' hm/asv.stream.toml > big.toml
timeout 20 $B stream big.toml --memory-gib 4 < hm/asv.input.jsonl > /dev/null 2> e22; rc=$?
say "22 stream (pf particles = 5e7) --memory-gib 4" "rc $rc $( [ $rc = 124 ] && echo '(accepted, still running at 20 s)'); $(line e22 | cut -c1-200)"
# 23 1000 tracked AUVs x 5e5 particles
{ printf 'name = "asv"\nframe = "ned"\n'; for i in $(seq 1000); do printf '[[tracked]]\nfrom = "given"\nt0_s = 0.0\nx_m = 50.0\ny_m = 0.0\nheading_deg = 90.0\n'; done; printf '[[estimators]]\nkind = "pf"\nparticles = 500000\n'; } > many.toml
# (its filters are built at the first line; virtual memory capped at 10 GB so that a
# binary that builds them fails without taking the machine)
head -50 hm/asv.input.jsonl > first.jsonl
(ulimit -v 10000000; timeout 20 $B stream many.toml --memory-gib 16 < first.jsonl > /dev/null 2> e23); rc=$?
say "23 stream (1000 tracked x 5e5 particles) --memory-gib 16" "rc $rc $( [ $rc = 124 ] && echo '(accepted, still running at 20 s)'); $(line e23 | cut -c1-200)"
# 24 every reader on /dev/zero and a FIFO
mkfifo fifo.toml
r24=""; for c in "run /dev/zero" "replay /dev/zero" "stream /dev/zero" "dsp simulate --config /dev/zero --out z.wav" "run fifo.toml"; do
  timeout 20 $B $c > /dev/null 2>&1 < /dev/null; r24="$r24 [$c: rc $?]"; done
say "24 /dev/zero and a FIFO as input" "$r24"
# 25 a rypkema stream with every line twice, ten times
$B scenarios --show rypkema-m1 | sed 's/^model = "channel" .*/model = "abstract"/; s/^duration_s = .*/duration_s = 600.0/' > m1.toml
$B run m1.toml --messages --out m1r > /dev/null 2>&1
$B stream m1r/platypus.stream.toml < m1r/platypus.input.jsonl > once.jsonl 2>/dev/null
for n in 2 10; do awk -v n=$n '{for (i = 0; i < n; i++) print}' m1r/platypus.input.jsonl > rep$n.jsonl; $B stream m1r/platypus.stream.toml < rep$n.jsonl > out$n.jsonl 2> e25-$n; done
say "25 stream rypkema-m1's platypus, every line x2 / x10" "x2: $(maxdev once.jsonl out2.jsonl 2) off the once-stream; x10: $(maxdev once.jsonl out10.jsonl 10), restarts $(grep -c 'started again' e25-10)"
# 26 a planner of 1000 x 1000 candidates; 27 setpoints beyond the vehicle
sed 's/^radii = .*/radii = 1000/; s/^angles = .*/angles = 1000/' hm/asv.stream.toml > slow.toml
timeout 30 $B stream slow.toml < hm/asv.input.jsonl > o26 2> e26; rc=$?
say "26 stream (controller radii = angles = 1000)" "rc $rc $( [ $rc = 124 ] && echo "(still deciding at 30 s, $(wc -l < o26) lines out)"); $(line e26 | cut -c1-200)"
r27=""; for kv in "lead_periods 1e9" "home_x_m 1e308"; do
  set -- $kv; sed "s/^$1 = .*/$1 = $2/" hm/asv.stream.toml > set.toml; timeout 20 $B stream set.toml < /dev/null > /dev/null 2>&1; r27="$r27 [$1 = $2: rc $?]"; done
sed '/^\[controller\]/,/^\[\[/ s/^depth_m = .*/depth_m = 1e9/' m1r/platypus.stream.toml > deep.stream.toml
grep -q '^depth_m = 1e9' deep.stream.toml && { timeout 20 $B stream deep.stream.toml < /dev/null > /dev/null 2>&1; r27="$r27 [behaviour depth_m = 1e9: rc $?]"; }
say "27 stream controllers: lead_periods, home_x_m, depth_m" "$r27"
# 28 a line array
printf '[array]\nkind = "custom"\nelements_m = [[0, 0, 0], [0.03, 0, 0], [0.06, 0, 0], [0.09, 0, 0]]\n' > line.toml
$B dsp simulate --config line.toml --out line.wav > o28 2> e28; rc=$?; c=""; [ $rc = 0 ] && c=$($B dsp process line.wav --config line.toml --json 2>&1 | tr -d ' ' | grep -o '"consistent":[a-z]*')
say "28 dsp simulate/process (4 elements on one line)" "rc $rc $c; $(line e28 | cut -c1-200)"
# 29 the sea's unbounded keys
r29=""; for kv in "clocks drift_sigma_ppm 1e9" "current speed_m_s 1e9" "link multipath_excess_m 1e9" "link loss_burst_mean 1e9"; do
  set -- $kv; printf 'name = "s"\n[mission]\nduration_s = 60\n[sea.%s]\n%s = %s\n' $1 $2 $3 > sea.toml
  $B mc sea.toml --runs 1 --json > /dev/null 2>&1; r29="$r29 [$1.$2: rc $?]"; done
say "29 mc with sea keys at 1e9" "$r29"
# 30 eight shards finishing at once
for i in $(seq 0 7); do $B mc short.toml --runs 8 --shard $i/8 --out p8 > /dev/null 2>&1 & done; wait
say "30 8 concurrent mc --shard i/8 --out p8" "partials listed in the marker: $(grep -c '^partial-' p8/.onebeacon-output)/8"
# 31 scripts/reproduce --only ''
(cd $REPO && ONEBEACON_CLI=$B timeout 20 scripts/reproduce --only '' > /dev/null 2>&1); rc=$?
say "31 scripts/reproduce --only ''" "rc $rc $( [ $rc = 124 ] && echo '(running every table)')"
# 32 smooth's memory estimate against a 600 000-row log
python3 - <<'P'
rows = 600000
with open('odo.csv', 'w') as f:
    f.write('t,d,dh\n'); f.writelines(f'{k * 0.1:.1f},0.1,0.001\n' for k in range(rows))
with open('truth.csv', 'w') as f:
    f.write('t,x,y,h\n'); f.writelines(f'{k * 0.1:.1f},0,0,0\n' for k in range(rows))
open('long.toml', 'w').write('name = "long"\nframe = "ned"\n[[source]]\nkind = "odometry"\nfile = "odo.csv"\ntime = "t"\ndistance = "d"\nheading_change = "dh"\n[[source]]\nkind = "ground_truth"\nfile = "truth.csv"\ntime = "t"\nx = "x"\ny = "y"\nheading = "h"\n[[estimators]]\nname = "dr"\nkind = "dead-reckoning"\n')
P
$B smooth long.toml --memory-gib 1e-9 --out s32 > /dev/null 2> e32
say "32 smooth (600 000 odometry + truth rows; 1016 MB measured)" "estimate: $(grep -o 'about [0-9.]* GB' e32)"
# 33 a file name with a line break beside others
$B dsp simulate --out "$(printf 'a\nb.wav')" > /dev/null 2> e33; rc=$?
say "33 dsp simulate --out 'a<newline>b.wav'" "rc $rc; marker lines: $( [ -f .onebeacon-output ] && wc -l < .onebeacon-output || echo none); $(line e33 | cut -c1-120)"
