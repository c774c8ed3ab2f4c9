"""Discrete chain element families (spec chain-models-1/2)."""
