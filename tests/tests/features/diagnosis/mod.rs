//! Fault diagnosis: faults and noise, banks of residual generators, Monte Carlo sweeps.

mod banks;
mod faults_and_noise;
mod sweep_outcome;
mod sweep_shards;
