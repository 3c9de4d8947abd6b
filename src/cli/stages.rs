//! `conemesh stages`: the registered implementations of each research extension point, with
//! their options (what `remesh --strategy/--param/--remesher NAME --*-opt KEY=VALUE` and `--improvers`
//! take).

use conemesh::registry::Entry;
use std::process::ExitCode;

/// Arguments of `conemesh stages` (none).
#[derive(clap::Args, Debug)]
pub struct StagesArgs {}

fn print_table<T: ?Sized>(title: &str, flag: &str, table: &[Entry<T>]) {
    println!("{title} ({flag} NAME, {flag}-opt KEY=VALUE; the first is the default):");
    print_rows(table);
}

/// Each row: name, summary, then its options with their defaults.
fn print_rows<T: ?Sized>(table: &[Entry<T>]) {
    for e in table {
        println!("  {:<8} {}", e.name, e.summary);
        for o in e.options {
            println!("           {:<16} {} {}", o.name, o.doc, o.defaults());
        }
    }
}

/// Run `conemesh stages`.
pub fn run(_: StagesArgs) -> anyhow::Result<ExitCode> {
    print_table(
        "patch strategies, Sec. 3.2",
        "--strategy",
        conemesh::patches::STRATEGIES,
    );
    print_table(
        "parameterizers, Sec. 3.3",
        "--param",
        conemesh::param::PARAMETERIZERS,
    );
    print_table(
        "planar remeshers, Sec. 3.3",
        "--remesher",
        conemesh::remesh2d::REMESHERS,
    );
    println!(
        "improvers, Sec. 3.4, run in order after the loop (--improvers A,B; --improver-opt NAME.KEY=VALUE; default: every one, {}):",
        conemesh::pipeline::default_improver_names().join(",")
    );
    print_rows(conemesh::improve::IMPROVERS);
    Ok(ExitCode::SUCCESS)
}
