"""Time the nonlinear batch simulator on the chapter 3 campaign (120 trials).

    python benchmarks/bench_simulator.py [--method rk4|euler] [--one-by-one 8] [--threads 1]

Prints the wall-clock time to simulate the whole campaign in batches (all
trials of one length together), then simulates a sample of the trials one
at a time and reports the per-trial ratio (one-by-one time per trial over
batched time per trial). Pins BLAS and OpenMP to ``--threads`` threads
before numpy loads, so the figure reflects the machine's cores honestly.
"""

from __future__ import annotations

import argparse
import os
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--method", choices=("rk4", "euler"), default="rk4")
    parser.add_argument("--one-by-one", type=int, default=8, help="trials simulated alone for the ratio")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[name] = str(args.threads)

    from simulator.campaign.fly import scenario_trials
    from simulator.campaign.scenario import load_builtin
    from simulator.flights.nonlinear import simulate_flights, truth_parameters
    from simulator.vehicle.presets import OCTO_S1000

    truth_parameters(OCTO_S1000)  # linearise once, outside the timing
    campaign = scenario_trials(load_builtin("chapter3-campaign"))
    steps = sum(round(t.duration_s * 400) for t in campaign)
    start = time.perf_counter()
    flights = simulate_flights(campaign, method=args.method)
    batch_s = time.perf_counter() - start
    flown = sum(f.time_s.size for f in flights) / 100.0
    print(f"campaign: {len(flights)} trials, {flown:.0f} s of flight, {steps} trial-steps at 400 Hz ({args.method})")
    print(
        f"batched:  {batch_s:6.1f} s wall  ({batch_s / len(flights) * 1e3:6.1f} ms per trial,"
        f" {flown / batch_s:5.0f}x real time)"
    )

    sample = campaign[:: max(1, len(campaign) // args.one_by_one)][: args.one_by_one]
    start = time.perf_counter()
    for trial in sample:
        simulate_flights([trial], method=args.method)
    alone_s = time.perf_counter() - start
    share = sum(t.duration_s for t in sample) / sum(t.duration_s for t in campaign)
    alone_total = alone_s / share
    print(
        f"alone:    {alone_s:6.1f} s for {len(sample)} trials -> {alone_total:6.1f} s for the campaign (extrapolated"
        f" by flight time)"
    )
    print(f"ratio:    one by one / batched = {alone_total / batch_s:5.1f}x per trial")


if __name__ == "__main__":
    main()
