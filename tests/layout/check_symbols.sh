#!/bin/sh
# Every dynamic symbol libedgespace defines starts with es_ (and none with es__).
nm_bin=$1 lib=$2
bad=$("$nm_bin" -D --defined-only "$lib" | awk '$2 ~ /^[TDBR]$/ {print $3}' | grep -v '^es_' ; \
      "$nm_bin" -D --defined-only "$lib" | awk '{print $3}' | grep '^es__')
if [ -n "$bad" ]; then echo "unexpected exports:"; echo "$bad"; exit 1; fi
count=$("$nm_bin" -D --defined-only "$lib" | awk '$2 == "T"' | grep -c '^.* es_')
[ "$count" -gt 0 ] || { echo "no es_ exports found"; exit 1; }
exit 0
