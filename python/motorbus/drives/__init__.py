"""Vendor drive clients and simulators, one module per vendor."""
