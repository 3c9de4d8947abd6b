//! What a comparison runs: named configurations (`NAME=ARGS` or a TOML file), inputs (files
//! or folders) and seeds (`1-5`, `1,3,7`), each checked before anything runs.

use super::{CompareError, ConfigDefect, InputDefect, SeedsDefect};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The extensions `conemesh` reads (see [`crate::io`]).
pub const MESH_EXTENSIONS: [&str; 5] = ["obj", "off", "ply", "stl", "mesh"];

/// The `conemesh remesh` arguments a comparison sets itself for every run: a configuration
/// that sets one would make every run fail or write where the comparison does not look.
pub const OWN_ARGS: [&str; 8] = [
    "-o",
    "--output",
    "--report",
    "--write-metric",
    "--seed",
    "-q",
    "--quiet",
    "--debug-dir",
];

/// One named configuration: `conemesh remesh` arguments.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Config {
    /// the name in tables and file names
    pub name: String,
    /// the `conemesh remesh` arguments
    pub args: Vec<String>,
}

impl Config {
    /// A configuration from `NAME=ARGS` (`kring=--strategy kring --strategy-opt rings=4`;
    /// `base=` for the defaults). ARGS is split at white space; quotes (`'…'`, `"…"`) keep
    /// white space inside one argument.
    pub fn parse(spec: &str) -> Result<Config, CompareError> {
        let (name, args) = spec.split_once('=').ok_or_else(|| CompareError::Config {
            what: spec.to_string(),
            defect: ConfigDefect::NotNameArgs,
        })?;
        Config::new(
            name.trim(),
            split_args(args).map_err(|e| CompareError::Config {
                what: spec.to_string(),
                defect: ConfigDefect::Quote(e),
            })?,
        )
    }

    /// A configuration with its name and arguments checked: the name is a non-empty word of
    /// letters, digits, `-`, `_` and `.` (it names files), and the arguments leave out
    /// [`OWN_ARGS`].
    pub fn new(name: &str, args: Vec<String>) -> Result<Config, CompareError> {
        let bad = |defect: ConfigDefect| CompareError::Config {
            what: name.to_string(),
            defect,
        };
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
            || name.starts_with('.')
        {
            return Err(bad(ConfigDefect::BadName {
                name: name.to_string(),
            }));
        }
        if let Some(a) = args
            .iter()
            .find(|a| OWN_ARGS.contains(&a.split('=').next().unwrap_or(a)))
        {
            return Err(bad(ConfigDefect::OwnArg { arg: a.clone() }));
        }
        Ok(Config {
            name: name.to_string(),
            args,
        })
    }
}

/// An argument line whose quote is not closed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unclosed quote {quote} in `{line}`")]
pub struct UnclosedQuote {
    /// the quote character
    pub quote: char,
    /// the line
    pub line: String,
}

/// Split `s` at white space, keeping quoted stretches (`'…'` or `"…"`) in one argument.
pub fn split_args(s: &str) -> Result<Vec<String>, UnclosedQuote> {
    let mut out = Vec::new();
    let mut cur: Option<String> = None;
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => cur.get_or_insert_with(String::new).push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                cur.get_or_insert_with(String::new);
            }
            (None, c) if c.is_whitespace() => out.extend(cur.take()),
            (None, c) => cur.get_or_insert_with(String::new).push(c),
        }
    }
    if let Some(q) = quote {
        return Err(UnclosedQuote {
            quote: q,
            line: s.to_string(),
        });
    }
    out.extend(cur);
    Ok(out)
}

/// Seeds from `1-5` (inclusive), `3`, or a comma-separated list of both (`1-3,7`); sorted,
/// without repeats.
pub fn parse_seeds(spec: &str) -> Result<Vec<u64>, CompareError> {
    let bad = |defect: SeedsDefect| CompareError::Seeds {
        spec: spec.to_string(),
        defect,
    };
    let num = |s: &str| {
        s.trim().parse::<u64>().map_err(|_| {
            bad(SeedsDefect::NotASeed {
                part: s.trim().to_string(),
            })
        })
    };
    let mut seeds = Vec::new();
    for part in spec.split(',') {
        match part.split_once('-') {
            Some((a, b)) => {
                let (a, b) = (num(a)?, num(b)?);
                if a > b {
                    return Err(bad(SeedsDefect::EmptyRange { start: a, end: b }));
                }
                if b - a >= 10_000 {
                    return Err(bad(SeedsDefect::TooMany { start: a, end: b }));
                }
                seeds.extend(a..=b);
            }
            None => seeds.push(num(part)?),
        }
    }
    seeds.sort_unstable();
    seeds.dedup();
    Ok(seeds)
}

/// The configurations of a TOML file, in file order:
///
/// ```toml
/// [[config]]
/// name = "cone"
/// args = ""                                            # the defaults
/// [[config]]
/// name = "kring"
/// args = ["--strategy", "kring", "--strategy-opt", "rings=4"]  # or one string
/// ```
pub fn read_config_file(path: &Path) -> Result<Vec<Config>, CompareError> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct File {
        config: Vec<Entry>,
    }
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Entry {
        name: String,
        #[serde(default)]
        args: Args,
    }
    #[derive(Deserialize, Default)]
    #[serde(untagged)]
    enum Args {
        #[default]
        None,
        Line(String),
        List(Vec<String>),
    }
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CompareError::Os {
        path: file.clone(),
        source,
    })?;
    let parsed: File = toml::from_str(&text).map_err(|source| CompareError::ConfigToml {
        path: file.clone(),
        source,
    })?;
    parsed
        .config
        .into_iter()
        .map(|e| {
            let args = match e.args {
                Args::None => Vec::new(),
                Args::Line(s) => split_args(&s).map_err(|source| CompareError::ConfigQuote {
                    path: file.clone(),
                    source,
                })?,
                Args::List(l) => l,
            };
            Config::new(&e.name, args)
        })
        .collect()
}

/// Configurations checked as a set: at least one, no name twice.
pub fn check_configs(configs: &[Config]) -> Result<(), CompareError> {
    if configs.is_empty() {
        return Err(CompareError::Config {
            what: "(none)".into(),
            defect: ConfigDefect::None,
        });
    }
    for (i, c) in configs.iter().enumerate() {
        if configs[..i].iter().any(|d| d.name == c.name) {
            return Err(CompareError::Config {
                what: c.name.clone(),
                defect: ConfigDefect::SameName,
            });
        }
    }
    Ok(())
}

/// One input mesh: its path and its name in tables and file names (the file stem).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Input {
    /// the mesh file (absolute)
    pub path: PathBuf,
    /// the file stem
    pub name: String,
}

/// The mesh files of `paths` (each a mesh file, or a folder whose mesh files are taken, by
/// name), as absolute paths: a missing path, a folder without meshes or two inputs with one
/// name are errors naming them.
pub fn collect_inputs(paths: &[PathBuf]) -> Result<Vec<Input>, CompareError> {
    if paths.is_empty() {
        return Err(CompareError::Input {
            path: "(none)".into(),
            defect: InputDefect::None,
        });
    }
    let mut files = Vec::new();
    for p in paths {
        let bad = |defect: InputDefect| CompareError::Input {
            path: p.display().to_string(),
            defect,
        };
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|source| CompareError::Os {
                    path: p.display().to_string(),
                    source,
                })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.is_file() && is_mesh_file(f))
                .collect();
            if found.is_empty() {
                return Err(bad(InputDefect::NoMeshFile));
            }
            found.sort();
            files.extend(found);
        } else if p.is_file() {
            files.push(p.clone());
        } else {
            return Err(bad(InputDefect::Missing));
        }
    }
    let mut inputs: Vec<Input> = Vec::new();
    for f in files {
        let path = std::path::absolute(&f).map_err(|source| CompareError::Os {
            path: f.display().to_string(),
            source,
        })?;
        let name = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let Some(other) = inputs.iter().find(|i| i.name == name) {
            return Err(CompareError::Input {
                path: f.display().to_string(),
                defect: InputDefect::SameName {
                    name,
                    other: other.path.clone(),
                },
            });
        }
        inputs.push(Input { path, name });
    }
    Ok(inputs)
}

fn is_mesh_file(p: &Path) -> bool {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .is_some_and(|e| MESH_EXTENSIONS.contains(&e.as_str()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_parse_ranges_and_lists_and_refuse_empty_ranges() {
        assert_eq!(parse_seeds("1-5").expect("a range"), vec![1, 2, 3, 4, 5]);
        assert_eq!(parse_seeds("7,1-2,2").expect("a list"), vec![1, 2, 7]);
        let e = parse_seeds("5-1").unwrap_err().to_string();
        assert!(e.contains("5-1") && e.contains("empty"), "{e}");
        assert!(parse_seeds("a-3").is_err());
        assert!(parse_seeds("").is_err());
    }

    #[test]
    fn configurations_parse_names_and_quoted_arguments() {
        let c =
            Config::parse("kring=--strategy kring --strategy-opt 'rings=4'").expect("quoted args");
        assert_eq!(c.name, "kring");
        assert_eq!(c.args, ["--strategy", "kring", "--strategy-opt", "rings=4"]);
        assert_eq!(
            Config::parse("base=").expect("no args").args,
            Vec::<String>::new()
        );
        assert!(Config::parse("noequals").is_err());
        assert!(Config::parse("a/b=--sweeps 2").is_err());
        let own = Config::parse("x=--seed 3").unwrap_err().to_string();
        assert!(own.contains("--seed"), "{own}");
        assert_eq!(
            split_args("'open"),
            Err(UnclosedQuote {
                quote: '\'',
                line: "'open".into()
            })
        );
        let twice = [
            Config::parse("a=").expect("no args"),
            Config::parse("a=--sweeps 1").expect("one option"),
        ];
        assert!(check_configs(&twice).is_err());
        assert!(check_configs(&[]).is_err());
    }

    #[test]
    fn a_toml_file_lists_configurations_in_order() -> Result<(), Box<dyn std::error::Error>> {
        let dir = tempfile::tempdir()?;
        let p = dir.path().join("c.toml");
        std::fs::write(
            &p,
            "[[config]]\nname = \"cone\"\n[[config]]\nname = \"kring\"\nargs = \"--strategy kring\"\n[[config]]\nname = \"k4\"\nargs = [\"--strategy\", \"kring\", \"--strategy-opt\", \"rings=4\"]\n",
        )?;
        let c = read_config_file(&p)?;
        let names: Vec<&str> = c.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["cone", "kring", "k4"]);
        assert_eq!(c[2].args.len(), 4);
        std::fs::write(&p, "[[config]\nname = 1")?;
        let e = read_config_file(&p).unwrap_err().to_string();
        assert!(e.contains("c.toml"), "{e}");
        Ok(())
    }
}
