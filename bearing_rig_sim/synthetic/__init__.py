"""Generated test data: messages and recordings made without a running rig, for round trips,
benchmarks and scenario tests (:mod:`.traffic`: rig traffic at the bench's rates;
:mod:`.bench`: bench-like pulse recordings from a known slip history).
"""
