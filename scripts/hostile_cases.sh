#!/usr/bin/env bash
# The careless and hostile cases of issue 27, one line each (what the command did):
# run it with an older binary and with this one to see a change. Usage:
#   scripts/hostile_cases.sh ONEBEACON WORKDIR   (WORKDIR must not exist; it is made)
# With a binary from before issue 27, case 5 allocates up to 16 GB for 8 s and case 7
# reads /dev/zero until the memory runs out (the kernel kills it): run that on a
# machine with room to spare.
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
