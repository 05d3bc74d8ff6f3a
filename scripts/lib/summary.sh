# Sourced by the scripts that read the apps' JSON summaries (--json) and take medians of runs.

# field KEY [FILE]: the number after "KEY": in a JSON summary (FILE, or stdin); empty when the
# summary has no such number.
field() { { grep -o "\"$1\": *[-0-9.eE+]*" ${2:+"$2"} || true; } | head -1 | sed 's/.*: *//'; }

# median: the median of the numbers on stdin, one a line (the mean of the middle two of an even
# count).
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
