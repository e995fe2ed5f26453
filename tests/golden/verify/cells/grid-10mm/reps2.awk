# Two repetitions on a 10 mm grid with check points, from the example's raw
# measurements (5 mm, two sets of ten): the first two readings of set 1 at
# the nodes of even index along both axes (and the last line), and at the
# nodes of odd index along both axes, the 10 mm cells' centres, as check
# points. Pass the raw file twice: awk -F, -f reps2.awk RAW RAW.
BEGIN { OFS = "," }
NR == FNR {
  if ($0 ~ /^#/ || $1 == "axis") next
  if (!(($1, "x0") in lo) || $2 < lo[$1, "x0"]) lo[$1, "x0"] = $2
  if (!(($1, "y0") in lo) || $3 < lo[$1, "y0"]) lo[$1, "y0"] = $3
  if ($2 > hi[$1, "x"]) hi[$1, "x"] = $2
  if ($3 > hi[$1, "y"]) hi[$1, "y"] = $3
  next
}
/^#/ { next }
$1 == "axis" { print $0 ",kind"; next }
$4 != 1 || $5 > 2 { next }
{
  i = int(($2 - lo[$1, "x0"]) / 5 + 0.5); j = int(($3 - lo[$1, "y0"]) / 5 + 0.5)
  xlast = $2 == hi[$1, "x"]; ylast = $3 == hi[$1, "y"]
  if ((i % 2 == 0 || xlast) && (j % 2 == 0 || ylast)) print $0, "node"
  else if (i % 2 == 1 && j % 2 == 1 && !xlast && !ylast) print $0, "check"
}
