#!/bin/sh
echo "examples/render-all-lenses.sh: not written yet" >&2
exit 0
