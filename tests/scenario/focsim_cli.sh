#!/bin/sh
# focsim from the command line: a run writes its CSV (with the contracted
# columns) and SVG and prints the summary keys; a malformed scenario line
# is rejected with its line number and a non-zero exit; bad options too.
set -u
focsim=$1
dir=$2
mkdir -p "$dir"
fail=0
check() { if ! eval "$2"; then echo "FAIL: $1"; fail=1; else echo "ok: $1"; fi; }

cat > "$dir/short.scn" <<'SCN'
# short run
0 start
0.1 speed 800   # trailing comment
0.8 end
SCN
"$focsim" --scenario "$dir/short.scn" --csv "$dir/short.csv" --plot "$dir/short.svg" \
    --decimate 10 > "$dir/summary.txt"
check "run exits 0" "[ $? -eq 0 ]"
check "csv header" "head -1 '$dir/short.csv' | grep -qx 't_s,state,fault,speed_ref_rpm,speed_rpm,speed_est_rpm,theta_e_deg,theta_est_deg,id_a,iq_a,id_ref_a,iq_ref_a,vd_v,vq_v,vdc_v,torque_nm,ia_a,ib_a,ic_a'"
rows=$(($(wc -l < "$dir/short.csv") - 1))
check "decimated rows (16001 periods / 10 -> 1601, got $rows)" "[ $rows -eq 1601 ]"
check "svg written" "grep -q '<svg' '$dir/short.svg'"
for key in final_state fault closed_loop_time_s speed_rpm_final; do
    check "summary has $key" "grep -q '^$key=' '$dir/summary.txt'"
done
check "reaches RUN" "grep -qx 'final_state=RUN' '$dir/summary.txt'"

printf '0 start\n0.1 speed 1000\n0.2 sped 500\n0.3 end\n' > "$dir/bad.scn"
"$focsim" --scenario "$dir/bad.scn" > /dev/null 2> "$dir/bad.err"
rc=$?
check "malformed line: non-zero exit" "[ $rc -ne 0 ]"
check "malformed line: names line 3" "grep -q 'bad.scn:3' '$dir/bad.err'"

"$focsim" --estimator magic --scenario "$dir/short.scn" > /dev/null 2>&1
check "unknown estimator rejected" "[ $? -ne 0 ]"
"$focsim" --decimate 0 --scenario "$dir/short.scn" > /dev/null 2>&1
check "--decimate 0 rejected" "[ $? -ne 0 ]"
"$focsim" --scenario "$dir/does-not-exist.scn" > /dev/null 2>&1
check "missing scenario rejected" "[ $? -ne 0 ]"
exit $fail
