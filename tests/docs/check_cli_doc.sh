#!/usr/bin/env bash
# Fails when docs/cli.md is not what scripts/gen-cli-doc.sh writes from the binaries of <build>.
#   tests/docs/check_cli_doc.sh <source dir> <build dir>
set -euo pipefail
src="$1"
build="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
bash "$src/scripts/gen-cli-doc.sh" "$build" "$tmp/cli.md"
if ! diff -u "$src/docs/cli.md" "$tmp/cli.md"; then
  echo "docs/cli.md is stale: regenerate it with" >&2
  echo "  bash scripts/gen-cli-doc.sh $build docs/cli.md" >&2
  exit 1
fi
echo "docs/cli.md matches the --help of the binaries in $build/bin"
