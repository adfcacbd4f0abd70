//! Workload (being built)
