#!/bin/sh
# fuzz.smoke: smoke.sh SOURCE FUZZBUILD SECONDS — build every libFuzzer
# target with clang in FUZZBUILD (incremental after the first time) and run
# each for SECONDS (run.sh).  Exit 77 (CTest skip) where clang or its
# libFuzzer runtime (Debian libclang-rt-14-dev) is missing.
set -u
SRC=$1 FB=$2 SECS=$3
command -v clang > /dev/null || { echo "SKIP: no clang"; exit 77; }
t=$(mktemp -d)
printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n) { return 0; }\n' > "$t/f.c"
if ! clang -fsanitize=fuzzer "$t/f.c" -o "$t/f" 2> /dev/null; then
    rm -rf "$t"
    echo "SKIP: clang has no libFuzzer runtime"
    exit 77
fi
rm -rf "$t"
CC=clang CXX=clang++ cmake -S "$SRC" -B "$FB" -DSPLAT_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug > "$FB.configure.log" 2>&1 ||
    { cat "$FB.configure.log"; exit 1; }
cmake --build "$FB" -j 2 --target fuzz_targets splatc_cli > "$FB.build.log" 2>&1 ||
    { tail -40 "$FB.build.log"; exit 1; }
exec sh "$SRC/tests/fuzz/run.sh" "$FB" "$SECS"
