"""One formal harness per block: the block with its environment's assumptions, its safety properties and covers
(docs/formal.md lists them). Each harness file starts with Amaranth's ``# amaranth: UnusedElaboratable=no``: the
runner adds an opened block's elaborated ``Module`` in place of the block (``FormalHarness.open``)."""
