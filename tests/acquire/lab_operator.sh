#!/bin/sh
# The operator of the virtual lab (virtual_lab_main.cc), for `acquire capture --operator`: does
# what the capture asks by writing the lab's control files, then confirms (exit 0). Every request
# is also appended to $control/asked as "<action> <argument>" (what the tests count).
#   lab_operator.sh <action> <argument> <request>
# $LUMISLAB_LAB_CONTROL is the lab's control folder.
set -eu
control="${LUMISLAB_LAB_CONTROL:?the virtual lab control folder}"
printf '%s %s\n' "$1" "$2" >> "$control/asked"
case "$1" in
  slide) printf '%s\n' "$2" > "$control/.slide" && mv "$control/.slide" "$control/slide" ;;
  board) printf '%s\n' "$2" > "$control/.board" && mv "$control/.board" "$control/board" ;;
  # capture --orientations: the luminaire remounted (mount <n>) or turned by hand (its name).
  mount) printf '%s\n' "$2" > "$control/.mount" && mv "$control/.mount" "$control/mount" ;;
  orientation)
    printf '%s\n' "$2" > "$control/.orientation" && mv "$control/.orientation" "$control/orientation" ;;
  *) echo "lab_operator.sh: cannot do '$1' ($3)" >&2; exit 1 ;;
esac
