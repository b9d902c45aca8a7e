"""Studies: the monolithic reference, accuracy against cost, the price of each effect."""
