#!/bin/sh
# tools/fresh-check.sh [-r <root dir>] [<repository>]
#
# `make sim` and `make test` on a bare machine: a minimal Debian (bookworm)
# root made by debootstrap with only gcc, cmake, make, python3 and git,
# the repository's HEAD cloned into it (uncommitted changes are not
# checked), both commands run there in a chroot as an unprivileged user.
# The tests that need an optional tool must be reported as skipped
# (README.md, "Tests and optional tools").  Exits with the first failing
# make's status.
#
#   <repository>   default: the repository this script is in
#   -r <root dir>  where the Debian root is kept between runs (the first
#                  run makes it: a few minutes); default $FOC_FRESH_ROOT,
#                  else /var/tmp/foc-fresh-root
#   FOC_FRESH_MIRROR  the Debian mirror (default: the first URIs of
#                  /etc/apt/sources.list.d/debian.sources, else
#                  http://deb.debian.org/debian)
#
# Needs root, debootstrap (apt-get install debootstrap) and the mirror.
# Not run by CI.
set -eu

root=${FOC_FRESH_ROOT:-/var/tmp/foc-fresh-root}
while getopts r: opt; do
    case $opt in
        r) root=$OPTARG ;;
        *) sed -n '2,20s/^# \{0,1\}//p' "$0" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
repo=${1:-$(dirname "$0")/..}
repo=$(git -C "$repo" rev-parse --show-toplevel)
head=$(git -C "$repo" rev-parse HEAD)

[ "$(id -u)" = 0 ] || { echo "fresh-check: needs root (debootstrap, chroot, mount)" >&2; exit 2; }
command -v debootstrap >/dev/null 2>&1 ||
    { echo "fresh-check: apt-get install debootstrap" >&2; exit 2; }

mirror=${FOC_FRESH_MIRROR:-$(sed -n 's/^URIs: *\([^ ]*\).*/\1/p' \
    /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -n 1)}
mirror=${mirror:-http://deb.debian.org/debian}

start=$(date +%s)
# The root is made once; the marker says debootstrap and the user are done.
if [ ! -f "$root/.foc-fresh-ready" ]; then
    echo "fresh-check: debootstrap bookworm into $root ($mirror)"
    rm -rf "$root"
    # minbase and --include install Depends only: libc6-dev (gcc's
    # Recommends) is what a gcc install on Debian brings along
    debootstrap --variant=minbase --include=gcc,libc6-dev,cmake,make,python3,git \
        bookworm "$root" "$mirror"
    chroot "$root" useradd --create-home foc
    touch "$root/.foc-fresh-ready"
fi

work=/home/foc/foc
rm -rf "$root$work"
git clone --quiet --no-checkout "$repo" "$root$work"
git -C "$root$work" checkout --quiet --detach "$head"
chroot "$root" chown -R foc:foc "$work"
echo "fresh-check: $repo at $head in $root$work"

cleanup() {
    umount "$root/dev/shm" 2>/dev/null || true
    umount "$root/dev/pts" 2>/dev/null || true
    umount "$root/dev" 2>/dev/null || true
    umount "$root/proc" 2>/dev/null || true
}
trap cleanup EXIT
trap 'exit 130' INT TERM
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"   # focsim --pty: pseudo-terminals
mount -t tmpfs tmpfs "$root/dev/shm"

# A clean environment: no CI, no host PATH or locale.
in_root() {
    chroot --userspec=foc:foc "$root" /usr/bin/env -i HOME=/home/foc \
        PATH=/usr/local/bin:/usr/bin:/bin sh -c "cd $work && $1"
}
status=0
echo "fresh-check: make sim"
in_root "make sim" || status=$?
echo "fresh-check: make test"
in_root "make test" || { s=$?; [ "$status" != 0 ] || status=$s; }
echo "fresh-check: status $status, $(($(date +%s) - start)) s"
exit "$status"
