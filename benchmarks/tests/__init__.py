"""Tests of the benchmarks' own code: how their sections and figures are written."""
