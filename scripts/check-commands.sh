#!/usr/bin/env bash
# Every command the README and the book show runs as shown.
#
# Extracts the commands of every ```sh and ```console block of README.md and docs/**/*.md
# (lines starting with `settle`, `cargo run` or `scripts/`; in console blocks, after `$ `;
# a trailing `\` continues a command on the next line) and runs them, page by page, each
# page in a fresh `git clone` of this repository in a temporary folder, with the working
# tree's uncommitted changes copied over. `settle` is the binary the test build made
# ($SETTLE_BIN, default $CARGO_TARGET_DIR/ci/settle) and `cargo run [--release] --` stands
# for it, so nothing is built again; a command with `--features` needs its own build and
# must be skipped.
#
# Skip a block that takes long or needs what the check cannot give (a network download,
# another build) with an HTML comment on the line before its fence:
#   <!-- check-commands: skip (the reason) -->
# The skipped commands are listed with their reasons at the end.
#
# Environment:
#   SETTLE_BIN                 the settle binary (default ${CARGO_TARGET_DIR:-target}/ci/settle)
#   SETTLE_COMMAND_TIMEOUT_S   time limit per command (default 600)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bin=${SETTLE_BIN:-${CARGO_TARGET_DIR:-target}/ci/settle}
[[ $bin = /* ]] || bin="$root/$bin"
if [[ ! -x $bin ]]; then
  echo "no settle binary at $bin: build it (cargo test --profile ci --no-run) or set SETTLE_BIN" >&2
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin"
ln -s "$bin" "$work/bin/settle"

# The commands, one NUL-terminated record each (a heredoc that writes a file the page uses
# next is one multi-line command): FILE, LINE, SKIP-REASON (empty: run it) and COMMAND,
# separated by the ASCII unit separator (a tab would merge with an empty field).
python3 - "$root" >"$work/commands.tsv" <<'EOF'
import glob, os, re, sys
root = sys.argv[1]
os.chdir(root)
files = ["README.md"] + sorted(glob.glob("docs/**/*.md", recursive=True))
skip_re = re.compile(r"<!--\s*check-commands:\s*skip\s*\((.*)\)\s*-->")
for f in files:
    lines = open(f, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        m = re.match(r"^\s*```+\s*(\w+)?", lines[i])
        if not m:
            i += 1
            continue
        lang = m.group(1) or ""
        prev = next((lines[k] for k in range(i - 1, -1, -1) if lines[k].strip()), "")
        s = skip_re.search(prev)
        reason = s.group(1).strip() if s else ""
        j = i + 1
        cmd, start = "", 0
        while j < len(lines) and not lines[j].strip().startswith("```"):
            line = lines[j].rstrip()
            j += 1
            if lang not in ("sh", "console"):
                continue
            if cmd:
                cmd += " " + line.strip().rstrip("\\").strip()
                if not line.endswith("\\"):
                    print(f"{f}\x1f{start}\x1f{reason}\x1f{cmd}", end="\0")
                    cmd = ""
                continue
            c = line.strip()
            if lang == "console":
                if not c.startswith("$ "):
                    continue
                c = c[2:]
            h = re.match(r"^cat\s*>\s*\S+\s*<<-?\s*'?(\w+)'?\s*$", c) if lang == "sh" else None
            if h:
                # A file the page writes with a heredoc: one command, run with the rest.
                body = [c]
                start = j
                while j < len(lines) and lines[j].strip() != h.group(1):
                    body.append(lines[j])
                    j += 1
                body.append(h.group(1))
                j += 1
                print(f"{f}\x1f{start}\x1f{reason}\x1f" + "\n".join(body), end="\0")
                continue
            if not re.match(r"^(settle|cargo run|scripts/)", c):
                continue
            start = j
            if c.endswith("\\"):
                cmd = c.rstrip("\\").strip()
            else:
                print(f"{f}\x1f{start}\x1f{reason}\x1f{c}", end="\0")
        i = j + 1
EOF

# A fresh clone of the working tree: the commits, then the uncommitted files.
clone() {
  local to=$1
  git clone -q "$root" "$to"
  (git ls-files -z -m -o --exclude-standard) | while IFS= read -r -d '' f; do
    if [[ -f $f ]]; then
      mkdir -p "$to/$(dirname "$f")"
      cp "$f" "$to/$f"
    fi
  done
}

timeout_s=${SETTLE_COMMAND_TIMEOUT_S:-600}
ran=0
failed=0
skipped=()
page=""
dir=""
while IFS=$'\x1f' read -r -d '' file line reason cmd; do
  if [[ -n $reason ]]; then
    skipped+=("$file:$line: $cmd  (skipped: $reason)")
    continue
  fi
  if [[ $file != "$page" ]]; then
    page=$file
    dir="$work/clone-$(echo "$file" | tr '/.' '__')"
    clone "$dir"
  fi
  # `cargo run [--release | --profile P] --` is the settle binary.
  run=$(echo "$cmd" | sed -E 's/^cargo run( --release| --profile [^ ]+)* -- /settle /')
  if [[ $run == cargo\ run* ]]; then
    echo "$file:$line: '$cmd' needs its own build: mark it <!-- check-commands: skip (reason) -->" >&2
    failed=$((failed + 1))
    continue
  fi
  echo "== $file:$line: $run"
  start=$(date +%s)
  if (cd "$dir" && PATH="$work/bin:$PATH" timeout "$timeout_s" bash -c "$run" >"$work/out.log" 2>&1); then
    echo "   ok ($(($(date +%s) - start)) s)"
  else
    echo "   FAILED ($(($(date +%s) - start)) s):" >&2
    tail -20 "$work/out.log" | sed 's/^/   | /' >&2
    failed=$((failed + 1))
  fi
  ran=$((ran + 1))
done <"$work/commands.tsv"

echo "== commands: $ran run, $failed failed, ${#skipped[@]} skipped"
for s in "${skipped[@]}"; do
  echo "   $s"
done
[[ $failed -eq 0 ]]
