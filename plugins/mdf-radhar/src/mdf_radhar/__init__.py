"""mdf-radhar: recorded point clouds of a TI IWR1443 mmWave radar (the RadHAR data set)."""
