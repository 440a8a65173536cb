#!/usr/bin/env bash
# Compiles every public header alone (include/ and glm only) and fails when one does not
# compile on its own or pulls in an OpenVDB, OpenMesh, TBB, Eigen, Boost, nlohmann or
# tinyxml2 header (those are private dependencies; Debian puts them in /usr/include, so the
# check reads the dependency list, not the include paths).
# Usage: check_headers.sh CXX INCLUDE_DIR
set -euo pipefail
cxx=$1 inc=$2
fail=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
while IFS= read -r h; do
  rel=${h#"$inc"/}
  # -MD (unlike -M) does not stop after preprocessing: the header is compiled too.
  if ! out=$(printf '#include "%s"\n' "$rel" |
             "$cxx" -std=c++17 -fsyntax-only -Wall -Wextra -Werror -I"$inc" -x c++ - \
                    -MD -MF "$tmp/deps" -MT x 2>&1); then
    echo "FAIL: $rel does not compile alone:"; echo "$out"; fail=1; continue
  fi
  deps=$(cat "$tmp/deps")
  leak=$(printf '%s\n' "$deps" | tr ' \\' '\n\n' | grep -Ei '/(openvdb|OpenMesh|tbb|oneapi|eigen3|boost|nlohmann|tinyxml2)' || true)
  if [[ -n $leak ]]; then echo "FAIL: $rel includes private dependencies:"; echo "$leak"; fail=1; fi
  n=$((${n:-0} + 1))
done < <(find "$inc" -name '*.h' | sort)
echo "checked ${n:-0} headers"
exit $fail
