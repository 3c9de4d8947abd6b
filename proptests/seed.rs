//! The seed and case count every property test runs with (included by each file).
//!
//! CI runs the same cases every time: the RNG seed is fixed per file, so a failure there is a
//! property broken by a change, not a new draw (a random draw once found a mutated file that
//! ran LCT out of memory; the CI run was killed after 83 minutes and the case was lost).
//! To explore other cases, `PROPTEST_RNG_SEED=<u64>` (proptest's own variable) replaces the
//! seed and `PROPTEST_CASES=<n>` the case counts; a failing case is written to the file's
//! regression list under `proptests/regressions/` and runs first from then on.

use proptest::test_runner::{Config, FileFailurePersistence, RngSeed};

/// The config of a file's property tests: `cases` cases, failures persisted in
/// `proptests/regressions/<stage>.txt`, the fixed seed `seed` (see [`seeded`]).
pub fn config(cases: u32, stage: &str, seed: u64) -> Config {
    let path: &'static str =
        Box::leak(format!("proptests/regressions/{stage}.txt").into_boxed_str());
    seeded(
        Config {
            cases,
            failure_persistence: Some(Box::new(FileFailurePersistence::Direct(path))),
            ..Config::default()
        },
        seed,
    )
}

/// `config` with the fixed seed `seed` (unless `PROPTEST_RNG_SEED` is set) and its case
/// count (unless `PROPTEST_CASES` is set).
pub fn seeded(config: Config, seed: u64) -> Config {
    let env = Config::default();
    let rng_seed = match env.rng_seed {
        RngSeed::Random => RngSeed::Fixed(seed),
        from_env => from_env,
    };
    let cases = match std::env::var_os("PROPTEST_CASES") {
        Some(_) => env.cases,
        None => config.cases,
    };
    Config {
        rng_seed,
        cases,
        ..config
    }
}
