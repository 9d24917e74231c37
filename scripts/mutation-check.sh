#!/usr/bin/env bash
# Mutation check of the default test suite (docs/testing.md, "Mutation check"):
# plants one deliberate bug at a time in the library, rebuilds ./build, runs
# the default suite (ctest -LE slow) and lists the tests that fail; then
# restores the file. A bug that no test catches is reported as SURVIVED and
# makes the script exit 1.
#   scripts/mutation-check.sh [NAME...]   (default: every mutation below)
# Needs a clean work tree for the mutated files (it restores them with git).
# Takes about 5-8 minutes per mutation on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
log_dir="${BF_MUTATION_LOG_DIR:-build/mutation}"
mkdir -p "$log_dir"

# name|file|perl substitution (must change the file)
mutations=(
  'transposed-projection|factor/projection.cpp|s/return \(u\.array\(\) \+ 1\.0\)\.matrix\(\) \* \(0\.5 \* \(res - 1\)\);/return (Eigen::Vector2d(u.y(), u.x()).array() + 1.0).matrix() * (0.5 * (res - 1));/'
  'laplacian-sign|factor/homomorphic_fit.cpp|s/val\[n\] = -1\.0;/val[n] = 1.0;/'
  'texel-off-by-one|factor/projection.cpp|s/const double x = std::clamp\(s\.x\(\), 0\.0, double\(res - 1\)\);/const double x = std::clamp(s.x() + 1.0, 0.0, double(res - 1));/'
  'exr-transpose|factor/export.cpp|s/for \(int c = 0; c < 3; \+\+c\) px\[3 \* k \+ c\] = t\.texels\[c\]\[k\];/for (int c = 0; c < 3; ++c) px[3 * ((k % R) * R + k \/ R) + c] = t.texels[c][k];/; s/const float v = px\[3 \* k \+ c\];/const float v = px[3 * ((k % R) * R + k \/ R) + c];/'
  'reciprocity-conjugate-dropped|factor/homomorphic.cpp|s/for \(int c = 0; c < 3; \+\+c\) s\[c\] \+= t\.lookup\(c, sc\);/(void)sc;/'
  'html-lt-not-escaped|experiments/escape.cpp|s/case \x27<\x27: o \+= "&lt;"; break;//'
  'html-amp-not-escaped|experiments/escape.cpp|s/case \x27&\x27: o \+= "&amp;"; break;//'
  'html-quot-not-escaped|experiments/escape.cpp|s/case \x27"\x27: o \+= "&quot;"; break;//'
  'markdown-newline-kept|experiments/escape.cpp|s/if \(is_line_break\(c\)\) o \+= \x27 \x27;/if (is_line_break(c)) o += char(c);/'
  'script-json-lt-kept|experiments/escape.cpp|s/if \(c == \x27<\x27\) o \+= "\\\\u003c";/if (false) o += "\\\\u003c";/'
)

want=("$@")
survived=0
for m in "${mutations[@]}"; do
  IFS='|' read -r name file subst <<< "$m"
  if [ ${#want[@]} -gt 0 ] && [[ ! " ${want[*]} " == *" $name "* ]]; then continue; fi
  git diff --quiet -- "$file" || { echo "mutation-check: $file has local changes: commit or stash them" >&2; exit 2; }
  cp "$file" "$log_dir/orig"
  perl -0pi -e "$subst" "$file"
  if cmp -s "$file" "$log_dir/orig"; then
    echo "mutation-check: $name: the substitution did not apply to $file (the code moved?)" >&2
    git checkout -- "$file"; exit 2
  fi
  echo "== $name ($file)"
  git diff -U0 -- "$file" | grep '^[-+][^-+]' | sed 's/^/   /'
  start=$(date +%s)
  if ! cmake --build build -j "$(nproc)" > "$log_dir/$name.build.log" 2>&1; then
    echo "   build FAILED (see $log_dir/$name.build.log)"; git checkout -- "$file"; exit 2
  fi
  (cd build && ctest -LE slow --no-tests=error --output-on-failure -j "$(nproc)" --timeout 600) > "$log_dir/$name.ctest.log" 2>&1 || true
  git checkout -- "$file"
  failed=$(sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (\(Failed\|Timeout\|SEGFAULT\|Subprocess aborted\|Exception\)).*$/\1/p' "$log_dir/$name.ctest.log")
  summary=$(grep -E 'tests passed, [0-9]+ tests failed' "$log_dir/$name.ctest.log" || echo "no ctest summary")
  echo "   $summary ($(( $(date +%s) - start )) s)"
  if [ -z "$failed" ]; then
    echo "   SURVIVED: no default test fails"; survived=1
  else
    echo "$failed" | sed 's/^/   fails: /'
  fi
done
# Rebuild the unmutated tree so ./build matches the sources again.
cmake --build build -j "$(nproc)" > "$log_dir/restore.build.log" 2>&1
exit $survived
