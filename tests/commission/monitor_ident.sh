#!/bin/sh
# Commissioning through the monitor (the board's path): focsim --pty at 20x
# wall time, foc-monitor `commission`, waits for its end, `ident` writes the
# motor file, which must carry the same Rs/Ld/Lq/flux and dead time focsim
# reports (id_rs_ohm ..., from the same results) and which tools/tune.py
# must accept.
#   monitor_ident.sh FOCSIM SRC_DIR WORK_DIR USERPARMS (the one focsim is built with)
set -u
focsim=$1 src=$2 work=$3 parms=$4
mkdir -p "$work"
rm -f "$work/ident.ini" "$work/focsim.err"
"$focsim" --pty --pace 20 --scenario "$src/tests/commission/monitor_ident.scn" \
    > "$work/focsim.out" 2> "$work/focsim.err" &
pid=$!
i=0
while ! grep -q '^pty: ' "$work/focsim.err" 2>/dev/null; do
    i=$((i + 1)); [ $i -lt 100 ] || { echo "no pty"; kill $pid; exit 1; }
    sleep 0.05
done
pty=$(sed -n 's/^pty: //p' "$work/focsim.err")
python3 "$src/tools/foc-monitor" --port "$pty" -e commission -e "wait COMMISSION 5" \
    -e "wait IDLE 20" -e comm-result \
    -e "ident userparms=$parms out=$work/ident.ini" || { kill $pid; exit 1; }
wait $pid || { echo "focsim failed"; exit 1; }
cat "$work/ident.ini"
fail=0
for k in rs_ohm:id_rs_ohm ld_h:id_ld_h lq_h:id_lq_h flux_linkage_wb:id_flux_wb \
         DEADTIME_EFFECTIVE_S:id_deadtime_s; do
    a=$(sed -n "s/^${k%%:*} = //p" "$work/ident.ini")
    b=$(sed -n "s/^${k#*:}=//p" "$work/focsim.out")
    python3 -c "import sys; a, b = float('$a'), float('$b'); sys.exit(0 if abs(a - b) <= 1e-4 * abs(b) else 1)" \
        && echo "ok   ${k%%:*} $a (focsim $b)" || { echo "FAIL ${k%%:*} $a, focsim $b"; fail=1; }
done
python3 "$src/tools/tune.py" --motor "$work/ident.ini" --board "$src/boards/dspicdem_mclv/board.ini" \
    --out "$work/userparms_ident.h" > /dev/null || { echo "FAIL tune.py refused the file"; fail=1; }
exit $fail
