#!/usr/bin/env bash
# Fetch the MuJoCo 3.17.0 shared library into the repository-local, git-ignored
# .deps/mujoco/ (settle's `mujoco` cargo feature links against it and finds it at run time
# through an rpath; nothing is installed system-wide).
#
# The library comes from the official PyPI wheel `mujoco==3.17.0` for this platform
# (pip download, no install): mujoco/libmujoco.so.3.17.0 is unzipped and symlinked as
# libmujoco.so. Idempotent: does nothing when the library is already there.
#
# Usage: scripts/setup-mujoco.sh        (from anywhere)
set -euo pipefail
cd "$(dirname "$0")/.."

VERSION=3.17.0
DEST=.deps/mujoco
LIB="libmujoco.so.${VERSION}"

if [[ -f "$DEST/$LIB" && -L "$DEST/libmujoco.so" && -e "$DEST/libmujoco.so" ]]; then
  echo "MuJoCo ${VERSION}: already present in $DEST"
  exit 0
fi

fail() {
  echo "setup-mujoco: $*" >&2
  exit 1
}

if [[ "$(uname -s)" != Linux ]]; then
  fail "only Linux is supported (the wheel's libmujoco.so); on $(uname -s) fetch MuJoCo ${VERSION} yourself and put libmujoco.so in $DEST"
fi
PIP=()
for py in python3 python; do
  if command -v "$py" >/dev/null && "$py" -m pip --version >/dev/null 2>&1; then
    PIP=("$py" -m pip)
    break
  fi
done
[[ ${#PIP[@]} -gt 0 ]] || fail "needs python3 with pip to download the mujoco==${VERSION} wheel (e.g. apt-get install python3-pip)"
command -v unzip >/dev/null || fail "needs unzip (e.g. apt-get install unzip)"

TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

echo "MuJoCo ${VERSION}: downloading the PyPI wheel (library only, nothing installed)..."
if ! "${PIP[@]}" download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
  --dest "$TMP" "mujoco==${VERSION}"; then
  fail "pip could not download mujoco==${VERSION} (no network to PyPI, or no wheel for this platform/python)"
fi
shopt -s nullglob
WHEELS=("$TMP"/mujoco-"${VERSION}"-*.whl)
[[ ${#WHEELS[@]} -eq 1 ]] || fail "expected one mujoco-${VERSION} wheel, found: ${WHEELS[*]:-none}"

unzip -q -o "${WHEELS[0]}" 'mujoco/libmujoco.so*' -d "$TMP/unz" ||
  fail "the wheel ${WHEELS[0]##*/} has no mujoco/libmujoco.so*"
[[ -f "$TMP/unz/mujoco/$LIB" ]] || fail "the wheel has no mujoco/$LIB"

# Assemble next to the destination, then move into place, so a failure never leaves a
# half-written library behind.
mkdir -p .deps
STAGE="$(mktemp -d .deps/mujoco.tmp.XXXXXX)"
chmod 755 "$STAGE"
cp "$TMP/unz/mujoco/$LIB" "$STAGE/$LIB"
ln -s "$LIB" "$STAGE/libmujoco.so"
rm -rf "$DEST"
mv "$STAGE" "$DEST"
echo "MuJoCo ${VERSION}: installed $DEST/$LIB ($(du -h "$DEST/$LIB" | cut -f1))"
