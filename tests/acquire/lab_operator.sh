#!/bin/sh
# The operator of the virtual lab (virtual_lab_main.cc), for `acquire capture --operator`: does
# what the capture asks by writing the lab's control files, then confirms (exit 0).
#   lab_operator.sh <action> <argument> <request>
# $LUMISLAB_LAB_CONTROL is the lab's control folder.
set -eu
control="${LUMISLAB_LAB_CONTROL:?the virtual lab control folder}"
case "$1" in
  slide) printf '%s\n' "$2" > "$control/.slide" && mv "$control/.slide" "$control/slide" ;;
  board) printf '%s\n' "$2" > "$control/.board" && mv "$control/.board" "$control/board" ;;
  *) echo "lab_operator.sh: cannot do '$1' ($3)" >&2; exit 1 ;;
esac
