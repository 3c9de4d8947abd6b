//! One registry table per research extension point (patch strategy, parameterizer, planar
//! remesher): name → constructor and its options. A new method is one new file plus one row
//! in its table ([`crate::patches::STRATEGIES`], [`crate::param::PARAMETERIZERS`],
//! [`crate::remesh2d::REMESHERS`]); `conemesh remesh --strategy/--param/--remesher NAME`
//! and `--strategy-opt/--param-opt/--remesher-opt KEY=VALUE` reach every row, and the
//! contract checks ([`crate::contract`]) run over every row.

use std::collections::BTreeMap;
use std::str::FromStr;
use thiserror::Error;

/// Errors of building a registered implementation.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum RegistryError {
    /// No row of that name.
    #[error("unknown {kind} `{name}` (known: {known})")]
    UnknownName {
        /// "patch strategy", "parameterizer", "planar remesher"
        kind: &'static str,
        /// the name asked for
        name: String,
        /// the names in the table
        known: String,
    },
    /// An option the row does not have.
    #[error("{kind} `{name}` has no option `{option}` (its options: {known})")]
    UnknownOption {
        /// the extension point
        kind: &'static str,
        /// the row
        name: &'static str,
        /// the option asked for
        option: String,
        /// the row's options
        known: String,
    },
    /// An option value that does not parse or is out of range.
    #[error("{kind} `{name}`, option `{option}`: `{value}` is not {expected}")]
    BadValue {
        /// the extension point
        kind: &'static str,
        /// the row
        name: &'static str,
        /// the option
        option: String,
        /// the value given
        value: String,
        /// what was expected
        expected: &'static str,
    },
    /// An option not written `KEY=VALUE`.
    #[error("option `{item}` is not of the form KEY=VALUE")]
    Malformed {
        /// the text given
        item: String,
    },
}

/// One option of a row: its name and what it means, with its default.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct OptionDoc {
    /// Name as written in `KEY=VALUE`.
    pub name: &'static str,
    /// Meaning and default.
    pub doc: &'static str,
}

/// The `KEY=VALUE` options given for one row. A constructor takes the ones it knows
/// ([`Params::take`]); [`build`] refuses any left over.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Params {
    given: BTreeMap<String, String>,
}

/// Why a constructor refused a value (turned into [`RegistryError::BadValue`] by [`build`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BadValue {
    option: String,
    value: String,
    expected: &'static str,
}

impl BadValue {
    /// Option `option` got `value`, which is not `expected`.
    pub fn new(option: &str, value: &str, expected: &'static str) -> BadValue {
        BadValue {
            option: option.to_string(),
            value: value.to_string(),
            expected,
        }
    }
}

impl Params {
    /// Parse `KEY=VALUE` strings (a later key wins).
    pub fn parse<S: AsRef<str>>(items: &[S]) -> Result<Params, RegistryError> {
        let mut given = BTreeMap::new();
        for item in items {
            let item = item.as_ref();
            let (k, v) = item
                .split_once('=')
                .filter(|(k, _)| !k.trim().is_empty())
                .ok_or_else(|| RegistryError::Malformed {
                    item: item.to_string(),
                })?;
            given.insert(k.trim().to_string(), v.trim().to_string());
        }
        Ok(Params { given })
    }

    /// Add or replace one option.
    pub fn set(&mut self, key: &str, value: impl ToString) {
        self.given.insert(key.to_string(), value.to_string());
    }

    /// True when option `key` is given.
    pub fn contains(&self, key: &str) -> bool {
        self.given.contains_key(key)
    }

    /// True when no option is left.
    pub fn is_empty(&self) -> bool {
        self.given.is_empty()
    }

    /// Take option `key` if given, parsed as `T` (`expected` names the type for the error).
    pub fn take<T: FromStr>(
        &mut self,
        key: &str,
        expected: &'static str,
    ) -> Result<Option<T>, BadValue> {
        let Some(v) = self.given.remove(key) else {
            return Ok(None);
        };
        v.parse().map(Some).map_err(|_| BadValue {
            option: key.to_string(),
            value: v,
            expected,
        })
    }

    /// [`Params::take`] for a value that must satisfy `valid` (`expected` says how).
    pub fn take_checked<T: FromStr + Copy>(
        &mut self,
        key: &str,
        expected: &'static str,
        valid: impl Fn(T) -> bool,
    ) -> Result<Option<T>, BadValue> {
        let raw = self.given.get(key).cloned();
        match self.take::<T>(key, expected)? {
            Some(x) if !valid(x) => Err(BadValue {
                option: key.to_string(),
                value: raw.unwrap_or_default(),
                expected,
            }),
            other => Ok(other),
        }
    }
}

/// One row of a registry: a name, a one-line summary, the options and the constructor.
pub struct Entry<T: ?Sized> {
    /// Name on the command line and in reports.
    pub name: &'static str,
    /// One line: what the method is (and its paper section or reference).
    pub summary: &'static str,
    /// The options the constructor takes.
    pub options: &'static [OptionDoc],
    /// Build the implementation from its options (the ones it takes are removed).
    pub build: fn(&mut Params) -> Result<Box<T>, BadValue>,
}

/// Build row `name` of `table` with `params`; `kind` names the extension point in errors.
pub fn build<T: ?Sized>(
    kind: &'static str,
    table: &[Entry<T>],
    name: &str,
    mut params: Params,
) -> Result<Box<T>, RegistryError> {
    let entry =
        table
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| RegistryError::UnknownName {
                kind,
                name: name.to_string(),
                known: names(table).join(", "),
            })?;
    let built = (entry.build)(&mut params).map_err(|b| RegistryError::BadValue {
        kind,
        name: entry.name,
        option: b.option,
        value: b.value,
        expected: b.expected,
    })?;
    if let Some(option) = params.given.keys().next() {
        return Err(RegistryError::UnknownOption {
            kind,
            name: entry.name,
            option: option.clone(),
            known: match entry.options {
                [] => "none".to_string(),
                o => o.iter().map(|o| o.name).collect::<Vec<_>>().join(", "),
            },
        });
    }
    Ok(built)
}

/// The names of a table, in order (the first is the default).
pub fn names<T: ?Sized>(table: &[Entry<T>]) -> Vec<&'static str> {
    table.iter().map(|e| e.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    trait Speak {
        fn word(&self) -> String;
    }
    struct Parrot(usize);
    impl Speak for Parrot {
        fn word(&self) -> String {
            "hello".repeat(self.0)
        }
    }
    fn parrot(p: &mut Params) -> Result<Box<dyn Speak>, BadValue> {
        let n = p.take_checked("times", "a positive integer", |n: usize| n > 0)?;
        Ok(Box::new(Parrot(n.unwrap_or(1))))
    }
    static TABLE: &[Entry<dyn Speak>] = &[Entry {
        name: "parrot",
        summary: "repeats",
        options: &[OptionDoc {
            name: "times",
            doc: "repetitions [1]",
        }],
        build: parrot,
    }];

    #[test]
    fn builds_by_name_with_options_and_refuses_what_it_does_not_know() {
        let p = |s: &[&str]| Params::parse(s).expect("parses");
        let b = build("speaker", TABLE, "parrot", p(&[])).expect("default");
        assert_eq!(b.word(), "hello");
        let b = build("speaker", TABLE, "parrot", p(&["times=2"])).expect("option");
        assert_eq!(b.word(), "hellohello");
        assert!(matches!(
            build("speaker", TABLE, "crow", p(&[])),
            Err(RegistryError::UnknownName { known, .. }) if known == "parrot"
        ));
        assert!(matches!(
            build("speaker", TABLE, "parrot", p(&["volume=3"])),
            Err(RegistryError::UnknownOption { option, known, .. })
                if option == "volume" && known == "times"
        ));
        for bad in ["times=0", "times=x", "times=-1"] {
            assert!(
                matches!(
                    build("speaker", TABLE, "parrot", p(&[bad])),
                    Err(RegistryError::BadValue { option, .. }) if option == "times"
                ),
                "{bad}"
            );
        }
        assert_eq!(
            Params::parse(&["times"]),
            Err(RegistryError::Malformed {
                item: "times".into()
            })
        );
        assert_eq!(
            Params::parse(&["=3"]),
            Err(RegistryError::Malformed { item: "=3".into() })
        );
    }
}
