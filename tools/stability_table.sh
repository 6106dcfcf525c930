#!/usr/bin/env bash
# Markdown summary of snapthread-stability's CSV: per sweep and method, for each budget,
# "spurious reversals / snap error in updates" ("missed" when a reference snap is missed),
# then "+k" when k snaps happened where the reference has none.
# usage: tools/stability_table.sh out/stability/stability.csv
set -euo pipefail
awk -F, '
NR == 1 { next }
{
  key = $1 "|" $2
  if (!(key in seen)) { seen[key] = 1; order[++n] = key }
  b = ($3 == 0) ? "inf" : $3
  err = ($9 < 0) ? "missed" : $9
  cell[key "|" b] = $6 " / " err ($10 > 0 ? " +" $10 : "")
  budgets[b] = 1
}
END {
  split("1 2 3 5 10 inf", bl, " ")
  printf "| sweep | method |"
  for (i = 1; i <= 6; ++i) printf " budget %s |", bl[i]
  printf "\n|---|---|"
  for (i = 1; i <= 6; ++i) printf "---|"
  printf "\n"
  for (k = 1; k <= n; ++k) {
    split(order[k], p, "|")
    printf "| %s | %s |", p[1], p[2]
    for (i = 1; i <= 6; ++i) { c = cell[order[k] "|" bl[i]]; printf " %s |", (c == "" ? "" : c) }
    printf "\n"
  }
}' "$1"
