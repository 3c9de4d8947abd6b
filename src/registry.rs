//! One registry table per research extension point (patch strategy, parameterizer, planar
//! remesher, improver). A row ([`Entry`]) is the one source of truth for its method: the name,
//! a summary, the options with their defaults (read from the method's own `Default`), and the
//! constructor. The built-in tables are [`crate::patches::STRATEGIES`],
//! [`crate::param::PARAMETERIZERS`], [`crate::remesh2d::REMESHERS`] and
//! [`crate::improve::IMPROVERS`]; the first row of each is the default stage (for improvers,
//! every row in order is the default list). A [`Registry`] starts from a built-in table and
//! takes rows written anywhere, in the crate or outside it.
//!
//! `conemesh remesh --strategy/--param/--remesher NAME`, `--improvers A,B` and
//! `--strategy-opt/--param-opt/--remesher-opt KEY=VALUE`, `--improver-opt NAME.KEY=VALUE`
//! reach every built-in row, and the contract checks ([`crate::contract`]) run over every row.
//!
//! A row's constructor is told the kind of sizes of the run's metric ([`MetricSizes`]): a
//! user's metric asks for absolute sizes, and a method may set some of its defaults for them
//! (the cone strategy trims ragged expansions, LCT starts from the boundary with density
//! control). That is the one way a run asks for absolute sizes.

use std::collections::BTreeMap;
use std::str::FromStr;
use thiserror::Error;

/// The names a lookup could have matched, as data; printed comma-separated ("none" when
/// there are none).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Names(pub Vec<&'static str>);

impl std::fmt::Display for Names {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0.as_slice() {
            [] => f.write_str("none"),
            names => f.write_str(&names.join(", ")),
        }
    }
}

/// Errors of building a registered implementation.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum RegistryError {
    /// No row of that name.
    #[error("unknown {kind} `{name}` (known: {known})")]
    UnknownName {
        /// "patch strategy", "parameterizer", "planar remesher", "improver"
        kind: &'static str,
        /// the name asked for
        name: String,
        /// the names in the table
        known: Names,
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
        known: Names,
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
    /// A row whose constructor built an implementation of another name (`name()` must be
    /// the row's name: reports and `--improver-opt NAME.KEY` go by it).
    #[error("{kind} row `{row}` built an implementation named `{built}`")]
    WrongName {
        /// the extension point
        kind: &'static str,
        /// the row
        row: &'static str,
        /// the built implementation's `name()`
        built: &'static str,
    },
    /// A row added to a registry that already has a row of that name.
    #[error("{kind} `{name}` is already registered")]
    Duplicate {
        /// the extension point
        kind: &'static str,
        /// the name
        name: &'static str,
    },
}

/// The kind of sizes of a run's metric, which a row's constructor may set defaults for.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
pub enum MetricSizes {
    /// Sizes relative to the input: the curvature metric, scaled so that the target length is
    /// a multiple of the input's mean metric edge length (the paper's protocol).
    #[default]
    Relative,
    /// Absolute sizes: a user's metric, meant as given.
    Absolute,
}

impl MetricSizes {
    /// Both kinds, for checks that cover every default.
    pub const ALL: [MetricSizes; 2] = [MetricSizes::Relative, MetricSizes::Absolute];

    /// `Absolute` for a user's metric, else `Relative`.
    pub fn of_user_metric(user_metric: bool) -> MetricSizes {
        match user_metric {
            true => MetricSizes::Absolute,
            false => MetricSizes::Relative,
        }
    }
}

/// One option of a row: its name, what it means, and its default as data.
#[derive(Copy, Clone, Debug)]
pub struct OptionDoc {
    /// Name as written in `KEY=VALUE`.
    pub name: &'static str,
    /// Meaning (the default is [`OptionDoc::default`], not repeated here).
    pub doc: &'static str,
    /// The default for a metric of each kind of sizes, written as a `VALUE` the constructor
    /// takes (`none` for an option that is off). Read from the method's own defaults (its
    /// `Default` value), so the two cannot drift; the contract check
    /// [`crate::contract::registry_row`] holds that the constructor takes it.
    pub default: fn(MetricSizes) -> String,
}

impl OptionDoc {
    /// The defaults as one line: `[4]`, or `[4; 6 with a user metric]` where they differ.
    pub fn defaults(&self) -> String {
        let (rel, abs) = (
            (self.default)(MetricSizes::Relative),
            (self.default)(MetricSizes::Absolute),
        );
        match rel == abs {
            true => format!("[{rel}]"),
            false => format!("[{rel}; {abs} with a user metric]"),
        }
    }
}

/// `x` as an option value: `none` for `None`.
pub fn optional<T: ToString>(x: Option<T>) -> String {
    x.map_or_else(|| "none".to_string(), |x| x.to_string())
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

impl Params {
    /// [`Params::take_checked`] for an option that may be off: `none` turns it off
    /// (`Some(None)`).
    pub fn take_optional<T: FromStr + Copy>(
        &mut self,
        key: &str,
        expected: &'static str,
        valid: impl Fn(T) -> bool,
    ) -> Result<Option<Option<T>>, BadValue> {
        if self.given.get(key).is_some_and(|v| v == "none") {
            self.given.remove(key);
            return Ok(Some(None));
        }
        Ok(self.take_checked(key, expected, valid)?.map(Some))
    }
}

/// One row of a registry: a name, a one-line summary, the options and the constructor.
pub struct Entry<T: ?Sized> {
    /// Name on the command line and in reports; the built implementation's `name()` is this
    /// ([`build`] refuses a row that builds another).
    pub name: &'static str,
    /// One line: what the method is (and its paper section or reference).
    pub summary: &'static str,
    /// The options the constructor takes, with their defaults.
    pub options: &'static [OptionDoc],
    /// Build the implementation from its options (the ones it takes are removed), for a
    /// metric with `sizes`.
    pub build: fn(&mut Params, MetricSizes) -> Result<Box<T>, BadValue>,
}

impl<T: ?Sized> Clone for Entry<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: ?Sized> Copy for Entry<T> {}

/// An extension point's trait object (`dyn PatchStrategy`, …): what names it in errors, its
/// built-in table, and the name of a built implementation.
pub trait Stage: 'static {
    /// "patch strategy", "parameterizer", "planar remesher", "improver".
    const KIND: &'static str;
    /// The built-in rows, the default first.
    fn builtin() -> &'static [Entry<Self>];
    /// The implementation's `name()`.
    fn stage_name(&self) -> &'static str;
}

/// Build row `name` of `table` with `params` for a metric with `sizes`; the built
/// implementation must carry the row's name.
pub fn build<T: ?Sized + Stage>(
    table: &[Entry<T>],
    name: &str,
    mut params: Params,
    sizes: MetricSizes,
) -> Result<Box<T>, RegistryError> {
    let kind = T::KIND;
    let entry =
        table
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| RegistryError::UnknownName {
                kind,
                name: name.to_string(),
                known: Names(names(table)),
            })?;
    let built = (entry.build)(&mut params, sizes).map_err(|b| RegistryError::BadValue {
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
            known: Names(entry.options.iter().map(|o| o.name).collect()),
        });
    }
    if built.stage_name() != entry.name {
        return Err(RegistryError::WrongName {
            kind,
            row: entry.name,
            built: built.stage_name(),
        });
    }
    Ok(built)
}

/// The names of a table, in order (the first is the default).
pub fn names<T: ?Sized>(table: &[Entry<T>]) -> Vec<&'static str> {
    table.iter().map(|e| e.name).collect()
}

/// The name of the default row of an extension point (the first of its built-in table).
pub fn default_name<T: ?Sized + Stage>() -> &'static str {
    T::builtin().first().map_or("", |e| e.name)
}

/// The first row of `table` built with its default options for `sizes`: the default stage.
/// A built-in table's first row builds with its defaults (the contract checks hold it).
pub fn build_default<T: ?Sized + Stage>(
    table: &[Entry<T>],
    sizes: MetricSizes,
) -> Result<Box<T>, RegistryError> {
    let first = table.first().map_or("", |e| e.name);
    build(table, first, Params::default(), sizes)
}

/// The rows of one extension point: a built-in table and rows added to it from anywhere
/// (a method defined outside the crate is one row, [`Registry::with`]).
pub struct Registry<T: ?Sized + 'static> {
    rows: Vec<Entry<T>>,
}

impl<T: ?Sized + Stage> Default for Registry<T> {
    fn default() -> Self {
        Registry::builtin()
    }
}

impl<T: ?Sized + Stage> Registry<T> {
    /// The built-in rows.
    pub fn builtin() -> Registry<T> {
        Registry {
            rows: T::builtin().to_vec(),
        }
    }

    /// The same with `row` added last; refused when a row of that name exists.
    pub fn with(mut self, row: Entry<T>) -> Result<Registry<T>, RegistryError> {
        if self.rows.iter().any(|e| e.name == row.name) {
            return Err(RegistryError::Duplicate {
                kind: T::KIND,
                name: row.name,
            });
        }
        self.rows.push(row);
        Ok(self)
    }

    /// Every row, the default first.
    pub fn rows(&self) -> &[Entry<T>] {
        &self.rows
    }

    /// Build row `name` with `params` for a metric with `sizes` (see [`build`]).
    pub fn build(
        &self,
        name: &str,
        params: Params,
        sizes: MetricSizes,
    ) -> Result<Box<T>, RegistryError> {
        build(&self.rows, name, params, sizes)
    }
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
    impl Stage for dyn Speak {
        const KIND: &'static str = "speaker";
        fn builtin() -> &'static [Entry<Self>] {
            TABLE
        }
        fn stage_name(&self) -> &'static str {
            "parrot"
        }
    }
    fn parrot(p: &mut Params, _: MetricSizes) -> Result<Box<dyn Speak>, BadValue> {
        let n = p.take_checked("times", "a positive integer", |n: usize| n > 0)?;
        Ok(Box::new(Parrot(n.unwrap_or(1))))
    }
    static TABLE: &[Entry<dyn Speak>] = &[Entry {
        name: "parrot",
        summary: "repeats",
        options: &[OptionDoc {
            name: "times",
            doc: "repetitions",
            default: |_| "1".into(),
        }],
        build: parrot,
    }];

    #[test]
    fn builds_by_name_with_options_and_refuses_what_it_does_not_know() {
        let p = |s: &[&str]| Params::parse(s).expect("parses");
        let b = build(TABLE, "parrot", p(&[]), MetricSizes::Relative).expect("default");
        assert_eq!(b.word(), "hello");
        let b = build(TABLE, "parrot", p(&["times=2"]), MetricSizes::Relative).expect("option");
        assert_eq!(b.word(), "hellohello");
        assert!(matches!(
            build(TABLE, "crow", p(&[]), MetricSizes::Relative),
            Err(RegistryError::UnknownName { known, .. }) if known.0 == ["parrot"]
        ));
        assert!(matches!(
            build(TABLE, "parrot", p(&["volume=3"]), MetricSizes::Relative),
            Err(RegistryError::UnknownOption { option, known, .. })
                if option == "volume" && known.0 == ["times"]
        ));
        for bad in ["times=0", "times=x", "times=-1"] {
            assert!(
                matches!(
                    build(TABLE, "parrot", p(&[bad]), MetricSizes::Relative),
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
        // A row added to a registry builds by name; a second row of the same name is refused.
        static CROW: Entry<dyn Speak> = Entry {
            name: "crow",
            summary: "caws",
            options: &[],
            build: |_, _| Ok(Box::new(Parrot(2))),
        };
        let reg = Registry::<dyn Speak>::builtin()
            .with(CROW)
            .expect("a new name");
        assert_eq!(names(reg.rows()), ["parrot", "crow"]);
        // The crow's constructor builds a parrot: refused by name.
        assert!(matches!(
            reg.build("crow", p(&[]), MetricSizes::Relative),
            Err(RegistryError::WrongName {
                row: "crow",
                built: "parrot",
                ..
            })
        ));
        assert!(matches!(
            reg.with(TABLE[0]),
            Err(RegistryError::Duplicate { name: "parrot", .. })
        ));
        assert_eq!(
            Params::parse(&["=3"]),
            Err(RegistryError::Malformed { item: "=3".into() })
        );
    }
}
