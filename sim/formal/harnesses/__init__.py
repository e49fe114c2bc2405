"""One formal harness per block: the block with its environment's assumptions, its safety properties and covers
(docs/formal.md lists them)."""
