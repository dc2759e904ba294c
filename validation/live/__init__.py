"""Live compensation beside a machine over OPC UA: node layout, twin, service, journal (docs/live.md)."""
