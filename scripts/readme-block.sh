#!/usr/bin/env bash
# Prints the commands of README.md's shell block marked for CI: the ```sh block right after the line
# `<!-- ci: NAME -->`, so that CI runs the README's own words (scripts/colcon-check.sh, pip-check.sh).
# Fails when README.md has no such block. Usage: readme-block.sh NAME [README]
set -euo pipefail
name=$1
readme=${2:-$(cd "$(dirname "$0")/.." && pwd)/README.md}
block=$(awk -v mark="<!-- ci: $name -->" '
  $0 == mark { armed = 1; next }
  armed && /^```sh$/ { inside = 1; armed = 0; next }
  inside && /^```$/ { exit }
  inside { print }
' "$readme")
if [ -z "$block" ]; then
  echo "readme-block: no \`\`\`sh block after '<!-- ci: $name -->' in $readme" >&2
  exit 1
fi
printf '%s\n' "$block"
