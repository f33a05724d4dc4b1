# Helpers shared by the bench scripts (sourced, not run).

# The median of the numbers on standard input, one per line (%.6g).
median() { sort -g | awk '{ v[NR] = $1 } END { printf "%.6g", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# a / b as a pair's ratio (%.4g).
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.4g", a / b }'; }
