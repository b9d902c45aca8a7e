"""Physics pieces units are assembled from; each with its own energy bookkeeping."""
