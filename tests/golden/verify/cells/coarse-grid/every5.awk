# Keeps every 5th node of each axis table (and the last line, so the domain
# stays): pass the table twice, awk -F, -f every5.awk TABLE TABLE.
BEGIN { OFS = "," }
NR == FNR {
  if ($0 ~ /^#/ || $1 == "axis") next
  if (!(($1, "x0") in lo) || $2 < lo[$1, "x0"]) lo[$1, "x0"] = $2
  if (!(($1, "y0") in lo) || $3 < lo[$1, "y0"]) lo[$1, "y0"] = $3
  if ($2 > hi[$1, "x"]) hi[$1, "x"] = $2
  if ($3 > hi[$1, "y"]) hi[$1, "y"] = $3
  next
}
/^#/ || $1 == "axis" { print; next }
{
  i = int(($2 - lo[$1, "x0"]) / 5 + 0.5); j = int(($3 - lo[$1, "y0"]) / 5 + 0.5)
  if ((i % 5 == 0 || $2 == hi[$1, "x"]) && (j % 5 == 0 || $3 == hi[$1, "y"])) print
}
