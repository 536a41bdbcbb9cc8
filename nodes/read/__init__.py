"""The ``read.*`` nodes: geometry read from files (``files``), budgeted and located."""
