"""The studies layer: what a command does with a scene - prepare and run it, report its modes, Monte
Carlo over the bit-rock laws and its statistics, the operating window, the form catalogue and check."""
