#!/usr/bin/env bash
# Runs CTS case patterns in N parallel deqp-vk processes (one case list each), resuming after a crash; a case
# cut off by the time budget is "Timeout", one the process died in "Crash", the rest "NotReached". EXCLUDE (an
# extended regex) drops cases, by default acceleration_structures.* and opacity_micromap.*. STRIDE=k runs every k-th
# of the remaining cases (a sample spread over all groups). Prints counts per group; <outdir>/results.txt has one line
# per case (name, status, microseconds), <outdir>/messages.txt the result message of every case that did not pass,
# <outdir>/reports.txt the driver's reports on standard error (lines starting "vkrt: ") with the case they came in.
# PIN=k pins shard i to the k CPUs i*k .. i*k+k-1 (taskset) and sets VKRT_THREADS=k: each case then runs on k cores
# of its own, as on a k-core machine (PIN=2 with N=8 on the device machine's 16 cores: the 2-core VM's bound).
# Usage: run_parallel.sh <deqp-vk> <ICD manifest> <N> <budget_s> <outdir> <pattern>...
set -u
bin=$(realpath "$1"); icd=$(realpath "$2"); n=$3; budget=$4; out=$(realpath -m "$5"); shift 5
mkdir -p "$out"; cd "$(dirname "$bin")"
# A second run into the same folder (a warm device machine keeps /tmp) starts clean: the shards' results, messages and
# done lists are appended to as a run goes, so an earlier run's would count again and its cases would be skipped.
rm -f "$out"/shard*
: > "$out/all.txt"
for p in "$@"; do
  rm -f TestResults.qpa dEQP-VK-cases.txt
  "$bin" --deqp-runmode=txt-caselist --deqp-case="$p" >/dev/null 2>&1
  grep '^TEST: ' dEQP-VK-cases.txt | sed 's/^TEST: //' >> "$out/all.txt"
done
grep -v -E "${EXCLUDE:-acceleration_structures\.|opacity_micromap\.}" "$out/all.txt" | awk -v k="${STRIDE:-1}" 'NR % k == 1 || k == 1' > "$out/cases.txt" || true
echo "cases: $(wc -l < "$out/cases.txt")"
awk -v n="$n" -v o="$out" '{print > (o "/shard" (NR % n) ".list")}' "$out/cases.txt"
deadline=$(( $(date +%s) + budget ))
shard() {
  local list=$1 index=$2 k=0
  local pin=()
  [ -n "${PIN:-}" ] && pin=(taskset -c "$((index * PIN))-$((index * PIN + PIN - 1))" env VKRT_THREADS="$PIN")
  while [ -s "$list" ] && [ "$(date +%s)" -lt "$deadline" ]; do
    k=$((k+1)); local log="$list.$k.qpa"
    timeout $(( deadline - $(date +%s) )) "${pin[@]}" env VK_DRIVER_FILES="$icd" "$bin" --deqp-caselist-file="$list" --deqp-log-filename="$log" \
      --deqp-log-images=disable --deqp-log-shader-sources=disable > "$list.$k.out" 2>&1
    local rc=$?
    # the driver's reports on stderr ("vkrt: ..."), each with the case that was running (at most 5 per case)
    awk '/^Test case / {c=$3; gsub(/[\047.]+$|^\047/, "", c); n=0} /^vkrt: / && n++ < 5 {print c "\t" $0}' "$list.$k.out" >> "$list.rep"
    rm -f "$list.$k.out"
    # results: name status duration_us
    awk '/^#beginTestCaseResult/ {c=$2; d=""} /Name="TestDuration"/ {match($0, />[0-9]+</); d=substr($0, RSTART+1, RLENGTH-2)}
         /StatusCode="/ {match($0, /StatusCode="[A-Za-z]*"/); s=substr($0, RSTART+12, RLENGTH-13)}
         /^#endTestCaseResult/ {print c, s, d; c=""} /^#terminateTestCaseResult/ {print c, "Crash"; c=""}
         END {if (c != "") print c, (rc == 124 ? "Timeout" : "Crash")}' rc=$rc "$log" >> "$list.res"
    # the message of each case that did not pass: name status text
    awk '/^#beginTestCaseResult/ {c=$2} /<Result StatusCode="/ {match($0, /StatusCode="[A-Za-z]*"/); s=substr($0, RSTART+12, RLENGTH-13)
         m=$0; sub(/.*<Result StatusCode="[A-Za-z]*">/, "", m); sub(/<\/Result>.*/, "", m); if (s != "Pass") print c, s, m}' "$log" >> "$list.msg"
    awk '{print $1}' "$list.res" | sort > "$list.done"
    sort "$list" | comm -23 - "$list.done" > "$list.rest"; mv "$list.rest" "$list"
  done
  [ -s "$list" ] && sed 's/$/ NotReached/' "$list" >> "$list.res"
  true
}
i=0
for f in "$out"/shard*.list; do shard "$f" "$i" & i=$((i + 1)); done; wait
cat "$out"/shard*.list.res > "$out/results.txt"
cat "$out"/shard*.list.msg > "$out/messages.txt" 2>/dev/null
cat "$out"/shard*.list.rep > "$out/reports.txt" 2>/dev/null
echo "--- all"; awk '{print $2}' "$out/results.txt" | sort | uniq -c
echo "--- per group (pass notsup fail other)"
awk '{split($1,a,"."); g=a[2]"."a[3]; t[g]++; if($2=="Pass")p[g]++; else if($2=="NotSupported")ns[g]++; else if($2=="Fail")f[g]++; else o[g]++}
     END {for (g in t) printf "%-60s %5d %5d %5d %5d\n", g, p[g], ns[g], f[g], o[g]}' "$out/results.txt" | sort
echo "--- slowest"; sort -k3 -n -r "$out/results.txt" | head -5
echo "--- not pass/notsupported"; grep -v -E ' (Pass|NotSupported|QualityWarning|CompatibilityWarning)( |$)' "$out/results.txt" | head -60
