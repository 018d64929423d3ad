"""Benchmarks: each module exposes add_arguments(parser) and run(args) -> Iterator[dict]."""
