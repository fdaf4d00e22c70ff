#!/usr/bin/env bash
# Fails when a tracked C++ file (git ls-files '*.cpp' '*.h') is not formatted as the repo's
# .clang-format says; lists every such file. Fix one with `clang-format -i <file>`.
set -o pipefail
repo="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$repo" || exit 2
command -v clang-format >/dev/null || { echo "clang-format is not installed" >&2; exit 2; }
mapfile -t files < <(git ls-files '*.cpp' '*.h')
if [ ${#files[@]} -eq 0 ]; then
  echo "no C++ files found under $repo (not a git checkout?)" >&2
  exit 2
fi
unformatted=()
for file in "${files[@]}"; do
  [ -f "$file" ] || continue  # deleted in the working tree, not yet committed
  clang-format --dry-run -Werror "$file" >/dev/null 2>&1 || unformatted+=("$file")
done
if [ ${#unformatted[@]} -gt 0 ]; then
  echo "${#unformatted[@]} of ${#files[@]} C++ files are not clang-formatted:"
  printf '  %s\n' "${unformatted[@]}"
  exit 1
fi
echo "${#files[@]} C++ files, all clang-formatted"
