"""Storage: the versioned HDF5 dataset, campaigns of logs and anemometer files, and their summaries."""
