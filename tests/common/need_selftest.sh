#!/bin/sh
# need.selftest <work dir>: tests/common/need.sh with a tool (clang) hidden
# from PATH skips the test (77) naming the package and logs it, under
# CI=true fails it (1) and logs nothing; with the tool found it runs the
# command and passes its status on (the command's own 77 as a failure);
# skip_summary.sh counts the log.
set -u
common=$(dirname "$0")
work=$1
sh=$(command -v sh)
fail() { echo "need.selftest: FAIL: $*"; exit 1; }
rm -rf "$work"
mkdir -p "$work/empty" "$work/fake"
printf '#!/bin/sh\n' > "$work/fake/clang"
chmod +x "$work/fake/clang"
log=$work/skipped.txt

out=$(PATH=$work/empty CI= FOC_SKIP_LOG=$log "$sh" "$common/need.sh" t.skip clang -- true)
st=$?
[ "$st" = 77 ] || fail "clang missing: exit $st, not 77"
case $out in *"apt-get install clang"*) ;; *) fail "no package named: $out" ;; esac

out=$(PATH=$work/empty CI=true FOC_SKIP_LOG=$log "$sh" "$common/need.sh" t.ci clang -- true)
st=$?
[ "$st" = 1 ] || fail "clang missing, CI=true: exit $st, not 1"
case $out in *FAIL*"apt-get install clang"*) ;; *) fail "CI=true: $out" ;; esac

PATH=$work/fake CI= FOC_SKIP_LOG=$log "$sh" "$common/need.sh" t.run clang -- "$sh" -c 'exit 3'
st=$?
[ "$st" = 3 ] || fail "clang found: exit $st, not the command's 3"
PATH=$work/fake CI= FOC_SKIP_LOG=$log "$sh" "$common/need.sh" t.77 clang -- "$sh" -c 'exit 77'
st=$?
[ "$st" = 1 ] || fail "the command's own 77: exit $st, not 1"

[ "$(cat "$log")" = "$(printf 't.skip\tclang')" ] || fail "skip log: $(cat "$log")"
summary=$("$sh" "$common/skip_summary.sh" "$log")
[ "$summary" = "skipped: 1 test (need clang: 1)" ] || fail "summary: $summary"
echo "need.selftest: ok"
