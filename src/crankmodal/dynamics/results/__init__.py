"""What a run gives: sampled histories, signals, per-revolution statistics, validity checks and figures."""
