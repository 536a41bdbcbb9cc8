"""formgraph: a node-graph procedural design engine."""
