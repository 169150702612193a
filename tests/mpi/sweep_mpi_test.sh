#!/usr/bin/env bash
# The MPI sweep on two ranks gives the same map as one process. MPI's runtime talks over TCP, so
# it runs in a private network namespace of its own (loopback only), never on the host's network.
# Usage: sweep_mpi_test.sh HAPTICSIM HAPTICSIM_SWEEP_MPI WORKDIR
set -euo pipefail
hapticsim=$1 sweep_mpi=$2 work=$3
mkdir -p "$work" && cd "$work"
cat > grid.toml <<'TOML'
[axes]
poisson_ratio = [0.40, 0.49]
youngs_modulus = [5000.0, 20000.0]
amplitude = [0.005, 0.01]
primary_size = [1, 3]
secondary_rate = [600.0, 1000.0]
TOML
scene=(--set mesh.nodes=9 --set input.frequency=2)
rm -f mpi.hsmap single.hsmap
unshare -rn sh -c 'ip link set lo up && exec "$@"' sh \
  mpirun --allow-run-as-root --oversubscribe --mca btl self,vader --mca oob_tcp_if_include lo \
  -np 2 "$sweep_mpi" --grid grid.toml "${scene[@]}" --out mpi.hsmap > mpi.json
"$hapticsim" sweep --grid grid.toml "${scene[@]}" --out single.hsmap --json > single.json 2>/dev/null
mpi=$(grep -o '"results_checksum": [0-9]*' mpi.json | grep -o '[0-9]*$')
single=$(grep -o '"results_checksum": [0-9]*' single.json | grep -o '[0-9]*$')
grep -q '"ranks": 2' mpi.json || { echo "FAIL: not two ranks: $(cat mpi.json)"; exit 1; }
grep -q '"not_computed": 0' mpi.json || { echo "FAIL: samples missing: $(cat mpi.json)"; exit 1; }
if [ "$mpi" != "$single" ]; then
  echo "FAIL: MPI map checksum $mpi differs from the single-process map's $single"
  exit 1
fi
"$hapticsim" map info mpi.hsmap > /dev/null
echo "PASS: 2 ranks, same results as one process (checksum $mpi)"
