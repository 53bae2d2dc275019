#!/usr/bin/env bash
# Pinocchio for a machine without network (the lent GPU machines, whose Intel Xeon CPU issue 24's
# CRBA row must be measured on): Pinocchio's wheels and those of the libraries it links, for one
# CPython version, reduced to the Python packages and the shared libraries their extensions load
# (about 18 MB compressed, where the installed wheels take 380 MB, over the 64 MiB a device call
# carries). numpy is not included: the target has its own.
#
#   bash benchmarks/pinocchio_bundle.sh [PYTHON_VERSION] [FOLDER]
#
# writes FOLDER/pinocchio-cpXY.tar.xz (defaults: 3.12, the lent machines' Python; .pinocchio, a
# folder git ignores). Unpack it anywhere and put DIR/cmeel.prefix/lib/pythonX.Y/site-packages on
# PYTHONPATH (benchmarks/intel_pending.sh does). The pin version is the lock file's.
set -euo pipefail
ver="${1:-3.12}"
folder="${2:-.pinocchio}"
root="$(cd "$(dirname "$0")/.." && pwd)"
pin="$(grep -E '^pin==' "$root/requirements.lock" | awk '{print $1}')"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
py="${PYTHON:-python3}"
"$py" -m pip download "$pin" --python-version "$ver" --only-binary=:all: \
    --platform manylinux_2_28_x86_64 -d "$work/wheels" -q
"$py" -m pip install --no-deps --no-compile --python-version "$ver" --only-binary=:all: \
    --platform manylinux_2_28_x86_64 --target "$work/site" -q \
    $(ls "$work"/wheels/*.whl | grep -v '/numpy-')
prefix="$work/site/cmeel.prefix"
site="lib/python$ver/site-packages"
out="$work/bundle/cmeel.prefix"
mkdir -p "$out/lib/python$ver"
cp -r "$prefix/$site" "$out/lib/python$ver/"
find "$out" -name __pycache__ -prune -exec rm -rf {} +
# the libraries the extensions load (found as the target's loader would: RUNPATH
# $ORIGIN/../lib): every one from the wheels, and from the system all but the C and C++
# runtimes every Linux with CPython and numpy has (libgomp, OpenMP, is not always there)
deps="$(for ext in $(find "$prefix/$site" -name '*.so'); do
    LD_LIBRARY_PATH="$prefix/lib:$prefix/lib64" ldd "$ext"
done)"
if grep -q "not found" <<< "$deps"; then
    echo "pinocchio_bundle: a library the extensions need is missing:" >&2
    grep "not found" <<< "$deps" | sort -u >&2
    exit 1
fi
system='/(libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so'
awk '$2 == "=>" {print $3}' <<< "$deps" | sort -u | grep -Ev "$system" | while read -r lib; do
    cp -L "$lib" "$out/lib/$(basename "$lib")"
done
mkdir -p "$root/$folder"
tag="cp${ver/./}"
tar -C "$work/bundle" -cJf "$root/$folder/pinocchio-$tag.tar.xz.part" cmeel.prefix
mv "$root/$folder/pinocchio-$tag.tar.xz.part" "$root/$folder/pinocchio-$tag.tar.xz"
ls -l "$root/$folder/pinocchio-$tag.tar.xz"
