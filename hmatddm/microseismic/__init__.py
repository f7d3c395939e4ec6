"""Synthetic microseismic events from simulations (ref. Ch. 7)."""
