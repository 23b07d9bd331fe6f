#!/usr/bin/env bash
# Long fuzzing run on the stable toolchain: every target of tests/fuzz_stable/targets.rs (each
# format crate's reader and the library's readers) for N mutated inputs, built with the `fuzz`
# profile (release speed with overflow checks and debug assertions) under a 2 GiB address-space
# cap, one process per target. Prints per target: executions, executions per
# second, panics, hangs, huge allocations, slow executions, the slowest execution and the peak
# resident memory. Failing inputs are saved under target/fuzz-findings/.
# usage: bench/fuzz.sh [EXECS_PER_TARGET] [TARGET...]   (default 1000000, or FUZZ_EXECS; all targets)
#        FUZZ_SEED=N picks another mutation sequence (default 1).
set -uo pipefail
cd "$(dirname "$0")/.."
execs=${1:-${FUZZ_EXECS:-1000000}}
shift $(( $# > 0 ? 1 : 0 ))
seed=${FUZZ_SEED:-1}
cargo build --profile fuzz --quiet --example fuzz_stable || exit 2
bin=./target/fuzz/examples/fuzz_stable
findings=target/fuzz-findings
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    mapfile -t targets < <("$bin" --list | awk '{print $1}')
fi
log=$(mktemp); trap 'rm -f "$log"' EXIT
status=0
echo "fuzz_stable: ${execs} executions per target, seed ${seed}, ulimit -v 2097152 (KiB)"
for t in "${targets[@]}"; do
    # Each target in its own process under the cap: an allocation the cap refuses aborts that
    # process only; the allocator's last message names the execution, whose input is then saved.
    ( ulimit -v 2097152; exec "$bin" --execs "$execs" --seed "$seed" --target "$t" --findings "$findings" ) >"$log" 2>&1
    rc=$?
    grep -v '^[0-9]* seeds of\|^skipped:' "$log" | grep -v '^allocation of' || true
    if [ $rc -gt 1 ]; then
        status=1
        exec_no=$(grep -o 'at execution [0-9]*' "$log" | tail -1 | awk '{print $3}')
        echo "$t: the process ended with status $rc: $(grep -v '^allocation of' "$log" | tail -1)"
        if [ -n "$exec_no" ]; then
            saved=$("$bin" --seed "$seed" --save-exec "$t:$exec_no" --findings "$findings")
            echo "  $(grep 'at execution' "$log" | tail -1); input saved to $saved"
        fi
    elif [ $rc -eq 1 ]; then
        status=1
    fi
done
exit $status
