#!/usr/bin/env bash
# The layering check: every folder of include/clearway/ and src/ is a pipeline stage, and a stage may
# include only itself and the stages before it. Reads every `#include <clearway/STAGE/...>` (and the
# plugin's, the tool's and the Python module's) and fails, naming file, line and both stages, when one
# points up the pipeline or names a stage not listed here. Headers at include/clearway/ itself (math.h,
# tolerances.h) and detail/ are below every stage. It also refuses a bare 1e-9 or 1e-12 in code (see
# the end).
set -euo pipefail
cd "$(dirname "$0")/.."

# The pipeline, from the bottom up: the one place its order is written.
stages=(detail shape narrowphase tree kinematics load body environment scene motion world ompl cli python)

rank() {
  local i
  for i in "${!stages[@]}"; do
    if [ "${stages[$i]}" = "$1" ]; then echo "$i"; return; fi
  done
  echo -1
}

# The stage a file belongs to, from its path.
stageOf() {
  case "$1" in
    include/clearway/*/*) local rest=${1#include/clearway/}; echo "${rest%%/*}" ;;
    include/clearway/*) echo "-" ;;
    src/*/*) local rest=${1#src/}; echo "${rest%%/*}" ;;
    plugins/ompl/*) echo ompl ;;
    python/*) echo python ;;
    *) echo "?" ;;
  esac
}

status=0
checked=0
while IFS= read -r file; do
  from=$(stageOf "$file")
  [ "$from" = "-" ] && from_rank=-1 || from_rank=$(rank "$from")
  if [ "$from" != "-" ] && [ "$from_rank" -lt 0 ]; then
    echo "check-layers: $file: its folder '$from' is not a stage (add it to the list in $0)"
    status=1
    continue
  fi
  while IFS=: read -r line target; do
    to=${target#*clearway/}
    case "$to" in */*) to=${to%%/*} ;; *) continue ;; esac  # (math.h, tolerances.h: below every stage)
    to_rank=$(rank "$to")
    checked=$((checked + 1))
    if [ "$to_rank" -lt 0 ]; then
      echo "check-layers: $file:$line: includes stage '$to', which is not in the list"
      status=1
    elif [ "$to_rank" -gt "$from_rank" ]; then
      echo "check-layers: $file:$line: stage '$from' includes '$to', which comes after it in the pipeline"
      status=1
    fi
  done < <(grep -noE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]clearway/[^>"]+' "$file" | sed -E 's/:[^<"]*[<"]/:/')
  # Relative includes that leave the file's own stage (../) bypass the check: refuse them.
  if grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"\.\./' "$file" >/dev/null; then
    echo "check-layers: $file: a relative include leaves its stage: $(grep -nE '#[[:space:]]*include[[:space:]]*"\.\./' "$file" | head -n 1)"
    status=1
  fi
done < <(find include/clearway src plugins/ompl python -type f \( -name '*.h' -o -name '*.cpp' \) | sort)

# No bare margin: a literal 1e-9 or 1e-12 in code (not in a comment or a string) must name what it is,
# as a constant (`constexpr double kName = 1e-9;`), or read include/clearway/detail/margins.h.
margins=0
while IFS= read -r hit; do
  echo "check-layers: $hit: a bare margin; use include/clearway/detail/margins.h or a named constant"
  margins=$((margins + 1))
  status=1
done < <(find include/clearway src plugins/ompl python -type f \( -name '*.h' -o -name '*.cpp' \) ! -path '*/detail/margins.h' -print0 |
  xargs -0 grep -nE '1e-(9|12)\b' | sed -E 's#//.*$##; s#"([^"\\]|\\.)*"#""#g' |
  grep -E ':[0-9]+:.*\b1e-(9|12)\b' | grep -vE ':[0-9]+:[[:space:]]*(static )?constexpr double k[A-Za-z0-9_]* = 1e-(9|12);' || true)

if [ $status -eq 0 ]; then
  echo "check-layers: $checked includes, all down the pipeline (${stages[*]}); no bare margin"
fi
exit $status
