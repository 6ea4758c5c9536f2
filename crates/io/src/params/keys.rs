//! Dotted key paths into a study table: `damping.alpha`, `excitation.levels[0]`,
//! `joint.blade1.threshold` (an array of tables — `[[joint]]`, `[[load]]`, `[[output]]` — is
//! entered by the `name` of one of its tables, or by an index: `joint[0].threshold`).

use std::fmt;

use toml::{Table, Value};

use super::ParamError;

/// One step of a key path.
#[derive(Clone, Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// A parsed key path, e.g. `joint.blade1.threshold`.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyPath {
    text: String,
    segments: Vec<Segment>,
}

/// What a key holds in the base study: the varied values are written back with this type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberKind {
    Float,
    /// An integer key (e.g. `harmonic_balance.harmonics`): samples are rounded to integers.
    Integer,
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl KeyPath {
    /// Parse `a.b[2].c`: names of ASCII letters, digits, `_` and `-`, each followed by any
    /// number of `[index]`.
    pub fn parse(text: &str) -> Result<KeyPath, ParamError> {
        let bad = |why: &str| ParamError::Key { key: text.to_string(), message: why.to_string() };
        if text.trim().is_empty() {
            return Err(bad("the key is empty; expected a dotted path such as `damping.alpha`"));
        }
        let mut segments = Vec::new();
        for part in text.split('.') {
            let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                return Err(bad(&format!(
                    "`{part}` is not a key: expected a name of ASCII letters, digits, `_` and `-`, then optional [index]"
                )));
            }
            segments.push(Segment::Key(name.to_string()));
            while !rest.is_empty() {
                let close = rest.find(']').ok_or_else(|| bad(&format!("`{part}`: `[` without `]`")))?;
                let index = rest[1..close].trim().parse::<usize>().map_err(|_| {
                    bad(&format!("`{part}`: index `{}` is not a non-negative integer", &rest[1..close]))
                })?;
                segments.push(Segment::Index(index));
                rest = &rest[close + 1..];
                if !rest.is_empty() && !rest.starts_with('[') {
                    return Err(bad(&format!("`{part}`: unexpected `{rest}` after `]`")));
                }
            }
        }
        Ok(KeyPath { text: text.to_string(), segments })
    }

    /// The key as written.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The kind of number the key holds in `table`. A key that the table does not set yet
    /// (e.g. `damping.beta` when only `alpha` is given) is a float if its parent exists; the
    /// study's validation then says whether the key is accepted at all.
    pub fn kind(&self, table: &Table) -> Result<NumberKind, ParamError> {
        match self.locate(table)? {
            Some(Value::Float(_)) => Ok(NumberKind::Float),
            Some(Value::Integer(_)) => Ok(NumberKind::Integer),
            Some(other) => {
                Err(self.error(format!("holds {}, not a number: only numeric values can be varied", described(other))))
            }
            None => Ok(NumberKind::Float),
        }
    }

    /// Write `value` at this key (created in its parent table if absent).
    pub fn set(&self, table: &mut Table, value: f64, kind: NumberKind) -> Result<(), ParamError> {
        let new = match kind {
            NumberKind::Float => Value::Float(value),
            NumberKind::Integer => Value::Integer(value.round() as i64),
        };
        let (last, parents) = self.segments.split_last().expect("a parsed key has a segment");
        let mut here = Value::Table(std::mem::take(table));
        let result = (|| {
            let parent = self.walk_mut(&mut here, parents)?;
            match (last, parent) {
                (Segment::Key(k), Value::Table(t)) => {
                    t.insert(k.clone(), new);
                    Ok(())
                }
                (Segment::Index(i), Value::Array(a)) if *i < a.len() => {
                    a[*i] = new;
                    Ok(())
                }
                (Segment::Index(i), Value::Array(a)) => Err(self.out_of_range(*i, a.len())),
                (Segment::Key(k), other) => Err(self.error(format!("`{k}` is looked up in {}", described(other)))),
                (Segment::Index(i), other) => Err(self.error(format!("[{i}] is looked up in {}", described(other)))),
            }
        })();
        let Value::Table(t) = here else { unreachable!("the root stays a table") };
        *table = t;
        result
    }

    /// The value at this key; `None` if only the last key is missing from an existing table.
    fn locate<'a>(&self, table: &'a Table) -> Result<Option<&'a Value>, ParamError> {
        // A parsed path starts with a key (the root is a table).
        let Segment::Key(first) = &self.segments[0] else { unreachable!("paths start with a name") };
        let mut cur = match table.get(first) {
            Some(v) => v,
            None if self.segments.len() == 1 => return Ok(None),
            None => return Err(self.missing(0)),
        };
        for depth in 1..self.segments.len() {
            let last = depth + 1 == self.segments.len();
            match self.step(cur, &self.segments[depth], depth)? {
                Some(v) => cur = v,
                None if last => return Ok(None),
                None => return Err(self.missing(depth)),
            }
        }
        Ok(Some(cur))
    }

    fn walk_mut<'a>(&self, root: &'a mut Value, parents: &[Segment]) -> Result<&'a mut Value, ParamError> {
        let mut cur = root;
        for (depth, s) in parents.iter().enumerate() {
            // Find the child's position first (immutably), then descend mutably.
            let position = match (s, &*cur) {
                (Segment::Key(k), Value::Table(t)) if t.contains_key(k) => Position::Key(k.clone()),
                (Segment::Key(k), Value::Array(a)) => match named(a, k) {
                    Some(i) => Position::Index(i),
                    None => return Err(self.missing(depth)),
                },
                (Segment::Index(i), Value::Array(a)) if *i < a.len() => Position::Index(*i),
                _ => return Err(self.step(cur, s, depth).err().unwrap_or_else(|| self.missing(depth))),
            };
            cur = match (position, cur) {
                (Position::Key(k), Value::Table(t)) => t.get_mut(&k).expect("checked above"),
                (Position::Index(i), Value::Array(a)) => &mut a[i],
                _ => unreachable!("the position matches the value's type"),
            };
        }
        Ok(cur)
    }

    /// One step down from `cur`; `Ok(None)` when a table lacks the key.
    fn step<'a>(&self, cur: &'a Value, s: &Segment, depth: usize) -> Result<Option<&'a Value>, ParamError> {
        match (s, cur) {
            (Segment::Key(k), Value::Table(t)) => Ok(t.get(k)),
            (Segment::Key(k), Value::Array(a)) => match named(a, k) {
                Some(i) => Ok(Some(&a[i])),
                None => {
                    let names: Vec<String> = a
                        .iter()
                        .filter_map(|v| v.get("name").and_then(Value::as_str).map(|n| format!("{n:?}")))
                        .collect();
                    Err(self.error(format!(
                        "`{}` has no table named {k:?} (names: {})",
                        self.prefix(depth),
                        if names.is_empty() { "none".to_string() } else { names.join(", ") }
                    )))
                }
            },
            (Segment::Index(i), Value::Array(a)) => a.get(*i).map(Some).ok_or_else(|| self.out_of_range(*i, a.len())),
            (Segment::Key(k), other) => {
                Err(self.error(format!("`{}` is {}, which has no key `{k}`", self.prefix(depth), described(other))))
            }
            (Segment::Index(i), other) => Err(self.error(format!(
                "`{}` is {}, not a list: [{i}] does not apply",
                self.prefix(depth),
                described(other)
            ))),
        }
    }

    /// The path up to and excluding segment `depth`.
    fn prefix(&self, depth: usize) -> String {
        let mut out = String::new();
        for s in &self.segments[..depth] {
            match s {
                Segment::Key(k) if out.is_empty() => out.push_str(k),
                Segment::Key(k) => {
                    out.push('.');
                    out.push_str(k);
                }
                Segment::Index(i) => out.push_str(&format!("[{i}]")),
            }
        }
        out
    }

    fn missing(&self, depth: usize) -> ParamError {
        let what = match &self.segments[depth] {
            Segment::Key(k) => format!("`{k}`"),
            Segment::Index(i) => format!("[{i}]"),
        };
        let at = if depth == 0 { "the study".to_string() } else { format!("`{}`", self.prefix(depth)) };
        self.error(format!(
            "{at} has no {what}; only values the study sets (or keys of a section it has) can be varied"
        ))
    }

    fn out_of_range(&self, index: usize, len: usize) -> ParamError {
        self.error(format!("index {index} is out of range: the list has {len} value(s)"))
    }

    fn error(&self, message: String) -> ParamError {
        ParamError::Key { key: self.text.clone(), message }
    }
}

enum Position {
    Key(String),
    Index(usize),
}

/// The index of the table named `name` in an array of tables.
fn named(a: &[Value], name: &str) -> Option<usize> {
    a.iter().position(|v| v.get("name").and_then(Value::as_str) == Some(name))
}

/// `a string "M"`, `an array [1, 2]`: a value with its type, for messages.
fn described(v: &Value) -> String {
    let t = v.type_str();
    let article = if t.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" };
    let text = v.to_string();
    // A whole table would be long: its type says enough.
    if matches!(v, Value::Table(_)) || text.len() > 60 {
        format!("{article} {t}")
    } else {
        format!("{article} {t} {text}")
    }
}
