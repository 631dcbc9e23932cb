#!/usr/bin/env bash
# Format and lint check of the whole tree: C++ with clang-format (.clang-format), Python with black
# (pyproject.toml) and flake8 (.flake8). Exit 0 when clean; otherwise the files and lines at fault.
# Fix with: clang-format -i <files>; black <files>. Run by the `lint` test (label lint).
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
missing=()
for tool in git clang-format black; do command -v "$tool" >/dev/null || missing+=("$tool"); done
/usr/bin/python3 -m flake8 --version >/dev/null 2>&1 || missing+=("flake8 (python3-flake8)")
if [ ${#missing[@]} -gt 0 ]; then
  echo "lint: not installed: ${missing[*]} (scripts/setup.sh installs them)" >&2
  exit 2
fi
# the files of the checkout (git knows them; build/ and runs/ are not among them)
mapfile -t cpp < <(git ls-files '*.cpp' '*.hpp' '*.h')
mapfile -t py < <(git ls-files '*.py')
status=0
clang-format --dry-run -Werror "${cpp[@]}" || { echo "lint: C++ not formatted (clang-format -i the files above)" >&2; status=1; }
black --check -q "${py[@]}" || { black --check "${py[@]}" 2>&1 | grep "would reformat" >&2; status=1; }
/usr/bin/python3 -m flake8 "${py[@]}" || status=1
[ $status -eq 0 ] && echo "lint: ${#cpp[@]} C++ and ${#py[@]} Python files clean"
exit $status
