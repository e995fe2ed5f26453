# A 10 mm grid with check points from a 5 mm table: the nodes of even index
# along both axes (and the last line, so the domain stays) are the nodes; the
# nodes of odd index along both axes, the centres of the 10 mm cells, are its
# check points (kind = check). Pass the table twice:
# awk -F, -f every2.awk TABLE TABLE.
BEGIN { OFS = "," }
NR == FNR {
  if ($0 ~ /^#/ || $1 == "axis") next
  if (!(($1, "x0") in lo) || $2 < lo[$1, "x0"]) lo[$1, "x0"] = $2
  if (!(($1, "y0") in lo) || $3 < lo[$1, "y0"]) lo[$1, "y0"] = $3
  if ($2 > hi[$1, "x"]) hi[$1, "x"] = $2
  if ($3 > hi[$1, "y"]) hi[$1, "y"] = $3
  next
}
/^#/ { print; next }
$1 == "axis" { print $0 ",kind"; next }
{
  i = int(($2 - lo[$1, "x0"]) / 5 + 0.5); j = int(($3 - lo[$1, "y0"]) / 5 + 0.5)
  xlast = $2 == hi[$1, "x"]; ylast = $3 == hi[$1, "y"]
  if ((i % 2 == 0 || xlast) && (j % 2 == 0 || ylast)) print $0, "node"
  else if (i % 2 == 1 && j % 2 == 1 && !xlast && !ylast) checks[++n] = $0 OFS "check"
}
END { for (k = 1; k <= n; ++k) print checks[k] }
