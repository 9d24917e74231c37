#!/usr/bin/env bash
# Mutation check of the default test suite (docs/testing.md, "Mutation check"):
# plants one deliberate bug at a time in the library, rebuilds ./build, runs
# the default suite (ctest -LE slow) and lists the tests that fail; then
# restores the file. A bug that no test catches is reported as SURVIVED and
# makes the script exit 1.
#   scripts/mutation-check.sh [NAME...]   (default: every mutation below)
# Needs a clean work tree for the mutated files (it restores them with git).
# Takes about 5-8 minutes per mutation on 2 cores.
#   scripts/mutation-check.sh --sample [NAME...]
# runs the independent sample instead (docs/testing.md, "Independent sample"):
# each mutant rebuilds only the test executable named with it and runs only the
# tests its spec selects (a lower bound on what the whole suite catches);
# about 1-3 minutes per mutant.
set -euo pipefail
cd "$(dirname "$0")/.."
log_dir="${BF_MUTATION_LOG_DIR:-build/mutation}"
mkdir -p "$log_dir"

# name|file|perl substitution (must change the file; write a '|' in it as \x7c)
mutations=(
  'transposed-projection|factor/projection.cpp|s/return \(u\.array\(\) \+ 1\.0\)\.matrix\(\) \* \(0\.5 \* \(res - 1\)\);/return (Eigen::Vector2d(u.y(), u.x()).array() + 1.0).matrix() * (0.5 * (res - 1));/'
  'laplacian-sign|factor/fit_internal.h|s/val\[n\] = -1\.0;/val[n] = 1.0;/'
  'texel-off-by-one|factor/projection.cpp|s/const double x = std::clamp\(s\.x\(\), 0\.0, double\(res - 1\)\);/const double x = std::clamp(s.x() + 1.0, 0.0, double(res - 1));/'
  'exr-transpose|factor/export.cpp|s/for \(int c = 0; c < 3; \+\+c\) px\[3 \* k \+ c\] = t\.texels\[c\]\[k\];/for (int c = 0; c < 3; ++c) px[3 * ((k % R) * R + k \/ R) + c] = t.texels[c][k];/; s/const float v = px\[3 \* k \+ c\];/const float v = px[3 * ((k % R) * R + k \/ R) + c];/'
  'reciprocity-conjugate-dropped|factor/homomorphic.cpp|s/for \(int c = 0; c < 3; \+\+c\) s\[c\] \+= t\.lookup\(c, sc\);/(void)sc;/'
  'html-lt-not-escaped|experiments/report/escape.cpp|s/case \x27<\x27: o \+= "&lt;"; break;//'
  'html-amp-not-escaped|experiments/report/escape.cpp|s/case \x27&\x27: o \+= "&amp;"; break;//'
  'html-quot-not-escaped|experiments/report/escape.cpp|s/case \x27"\x27: o \+= "&quot;"; break;//'
  'markdown-newline-kept|experiments/report/escape.cpp|s/if \(is_line_break\(c\)\) o \+= \x27 \x27;/if (is_line_break(c)) o += char(c);/'
  'script-json-lt-kept|experiments/report/escape.cpp|s/if \(c == \x27<\x27\) o \+= "\\\\u003c";/if (false) o += "\\\\u003c";/'
  'metrics-weights-ignored|factor/metrics.cpp|s/const Acc w = s\.weight_of\(k\);/const Acc w = 1;/'
  'peak-ratio-red-peak|factor/metrics.cpp|s/std::max\(fa\[c\], 0\.0\) \/ peak\[c\]/std::max(fa[c], 0.0) \/ peak[0]/'
  'holdout-never-last|experiments/report/validation.cpp|s/splitmix\(state\) % \(valid\.size\(\) - i\)\)/splitmix(state) % (valid.size() - i - 1))/'
  'svd-rim-inset-full-spacing|factor/svd_baseline.cpp|s/std::min\(0\.5, 1\.0 \/ std::max\(1, res - 1\)\)/std::min(0.5, 2.0 \/ std::max(1, res - 1))/'
  'split-planes-off-block-once|search/structure.cpp|s/o \+= 2 \* G\.block/o += G.block/'
  'split-planes-b-without-off|search/structure.cpp|s/double b = all - off - a;/double b = all - a;/'
  'reader-theta-up-to-pi|brdfs/measured_readers.cpp|s/v <= M_PI \/ 2 \+ kTol/v <= M_PI + kTol/'
  'csv-wi-below-horizon-used|brdfs/sampleset.cpp|s/if \(!\(wi\[k\]\.z\(\) > 0\.0\) \x7c\x7c /if (/'
  'run-id-without-holdout|experiments/config/config.cpp|s/\{"holdout", plan\.experiment\.holdout\},\n\s*//'
)

# The independent sample (docs/testing.md, "Independent sample"):
# name|file|perl substitution|test executable|Catch2 test spec
sample=(
  'm1-W-without-3|factor/metrics.cpp|s/W \+= 3 \* w;/W += w;/|test_factor|metrics:*'
  'm2-cos-unweighted|factor/metrics.cpp|s/cos_se \+= w \* dc \* dc;/cos_se += dc * dc;/|test_factor|metrics:*'
  'm3-cos-of-wo|factor/metrics.cpp|s/dc = df \* Acc\(s\.wi\[k\]\.z\(\)\);/dc = df * Acc(s.wo[k].z());/|test_factor|metrics:*'
  'm4-lin-mae-signed|factor/metrics.cpp|s/lin_ae \+= w \* std::abs\(df\);/lin_ae += w * df;/|test_factor|metrics:*'
  'm5-A-mean-off-by-one|factor/metrics.cpp|s/sum\[c\] \/ static_cast<long double>\(n\)/sum[c] \/ static_cast<long double>(n + 1)/|test_factor|metrics:*'
  'm6-peak-of-masked|factor/metrics.cpp|s/if \(s\.valid\[k\]\) \{\n      \+\+n;/{\n      ++n;/|test_factor|metrics:*'
  'm7-rel-max-weighted|factor/metrics.cpp|s/rel_max = std::max\(rel_max, std::abs\(dg\)\);/rel_max = std::max(rel_max, w * std::abs(dg));/|test_factor|metrics:*'
  'v1-masked-held-out|experiments/report/validation.cpp|s/if \(s\.valid\[k\]\) valid\.push_back\(k\);/valid.push_back(k);/|test_experiments|validation:*'
  'v2-held-weight-1|experiments/report/validation.cpp|s/dst\.weight\.push_back\(s\.weight\[k\]\);/dst.weight.push_back(1.0);/|test_experiments|validation:*'
  'v3-shuffle-without-offset|experiments/report/validation.cpp|s/const size_t j = i \+ static_cast/const size_t j = static_cast/|test_experiments|validation:*'
  'v4-count-of-all-samples|experiments/report/validation.cpp|s/fraction \* static_cast<double>\(valid\.size\(\)\)/fraction * static_cast<double>(s.size())/|test_experiments|validation:*'
  'v5-holdout-cos-from-domain|experiments/report/validation.cpp|s/format_number\(v\.held\.cos_rmse\)/format_number(v.val.cos_rmse)/|test_experiments|validation:*'
  's1-pull-in-unscaled|factor/svd_baseline.cpp|s/p \*= rmax \/ r;/p *= rmax;/|test_factor|svd:*'
  's2-inset-zero-kept|factor/svd_baseline.cpp|s/return rim_inset > 0\.0 \?/return rim_inset >= 0.0 ?/|test_factor|svd:*'
  's3-point-transposed|factor/svd_baseline.cpp|s/return Vec2\(-1\.0 \+ \(texel % res\) \* h, -1\.0 \+ \(texel \/ res\) \* h\);/return Vec2(-1.0 + (texel \/ res) * h, -1.0 + (texel % res) * h);/|test_factor|svd:*'
  's4-inside-strict|factor/svd_baseline.cpp|s/\.norm\(\) <= 1\.0 \+ 1e-12;/.norm() < 1.0 - 1e-12;/|test_factor|svd:*'
  's5-rim-elevation|factor/svd_baseline.cpp|s/z_min = \(1\.0 - rr \* rr\) \/ \(1\.0 \+ rr \* rr\)/z_min = (1.0 - rr) \/ (1.0 + rr)/|test_factor|svd:*'
  't1-plane-a-block-wrong|search/structure.cpp|s/s \+= G\.block<2, 2>\(0, 0\)/s += G.block<2, 2>(2, 2)/|test_search|structure:*'
  't2-share-of-b|search/structure.cpp|s/best\.share_a = a \/ all;/best.share_a = b \/ all;/|test_search|structure:*'
  't3-hessian-diagonal-halved|search/structure.cpp|s/if \(i == j\) H\(i, i\) = 2 \* v;/if (i == j) H(i, i) = v;/|test_search|structure:*'
  't4-total-of-norms|search/structure.cpp|s/all \+= H\.squaredNorm\(\);/all += H.norm();/|test_search|structure:*'
  'va1-auto-never-doubles|experiments/report/validation.cpp|s/    blocks = std::min\(2 \* blocks, d\.blocks\);/    break;/|test_experiments|validation auto:*'
  'va2-se-without-sqrt-n|experiments/report/validation.cpp|s/sd \/ std::sqrt\(static_cast<long double>\(n\)\) \/ mean/sd \/ mean/|test_experiments|validation auto:*'
  'r1-csv-theta-to-2pi|brdfs/sample_csv.cpp|s/hi = theta \? M_PI :/hi = theta ? 2.0 * M_PI :/|test_brdfs|~[slow]'
  'r2-csv-weight-dropped|brdfs/sample_csv.cpp|s/has_weight \? v\[7\] : 1\.0\);/1.0);/|test_brdfs|~[slow]'
  'r3-reader-negative-theta|brdfs/measured_readers.cpp|s/if \(!\(v >= 0\.0 && v <= M_PI \/ 2 \+ kTol\)\)/if (!(v <= M_PI \/ 2 + kTol))/|test_brdfs|~[slow]'
  'r4-reader-tolerance|brdfs/measured_readers.cpp|s/constexpr double kTol = 1e-6;/constexpr double kTol = 1e-1;/|test_brdfs|~[slow]'
  'r5-spectral-phi-swapped|brdfs/measured_readers.cpp|s/from_spherical\(a\[2\], a\[3\]\)/from_spherical(a[2], a[1])/|test_brdfs|~[slow]'
)

# Plants mutation $1 (name) in file $2 with perl substitution $3 and shows the
# changed lines; exits 2 when the file has local changes or the substitution
# does not apply.
plant() {
  local name=$1 file=$2 subst=$3
  git diff --quiet -- "$file" || { echo "mutation-check: $file has local changes: commit or stash them" >&2; exit 2; }
  cp "$file" "$log_dir/orig"
  perl -0pi -e "$subst" "$file"
  if cmp -s "$file" "$log_dir/orig"; then
    echo "mutation-check: $name: the substitution did not apply to $file (the code moved?)" >&2
    git checkout -- "$file"; exit 2
  fi
}

if [ "${1:-}" = "--sample" ]; then
  shift
  want=("$@")
  survived=0
  for m in "${sample[@]}"; do
    IFS='|' read -r name file subst target spec <<< "$m"
    if [ ${#want[@]} -gt 0 ] && [[ ! " ${want[*]} " == *" $name "* ]]; then continue; fi
    plant "$name" "$file" "$subst"
    echo "== $name ($file; $target \"$spec\")"
    git diff -U0 -- "$file" | grep '^[-+][^-+]' | sed 's/^/   /'
    if ! cmake --build build -j "$(nproc)" --target "$target" > "$log_dir/$name.build.log" 2>&1; then
      echo "   build FAILED (see $log_dir/$name.build.log)"; git checkout -- "$file"; exit 2
    fi
    rc=0
    timeout 900 "build/tests/$target" "$spec" > "$log_dir/$name.test.log" 2>&1 || rc=$?
    git checkout -- "$file"
    if [ "$rc" -eq 0 ]; then
      echo "   SURVIVED: no selected test fails"; survived=1
    else
      echo "   caught (exit $rc): $(grep -E '^test cases:' "$log_dir/$name.test.log" | tail -1)"
    fi
  done
  # Rebuild the executables used, so ./build matches the sources again.
  targets=$(for m in "${sample[@]}"; do IFS='|' read -r name _ _ target _ <<< "$m"
    if [ ${#want[@]} -eq 0 ] || [[ " ${want[*]} " == *" $name "* ]]; then echo "$target"; fi; done | sort -u)
  # shellcheck disable=SC2086
  cmake --build build -j "$(nproc)" --target $targets > "$log_dir/restore.build.log" 2>&1
  exit $survived
fi

want=("$@")
survived=0
for m in "${mutations[@]}"; do
  IFS='|' read -r name file subst <<< "$m"
  if [ ${#want[@]} -gt 0 ] && [[ ! " ${want[*]} " == *" $name "* ]]; then continue; fi
  plant "$name" "$file" "$subst"
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
