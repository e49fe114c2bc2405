"""The board flow: what turns the gateware into a Genesys (Virtex-5) build and what checks it (timing estimate)."""
