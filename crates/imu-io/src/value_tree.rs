//! A [`ParamValue`] tree read as any serde type, the way a file's parser would read the same
//! values: what a Python dict becomes on its way to a scenario ([`read`]).
//!
//! The tree is read directly, not re-encoded as TOML or JSON first: TOML's integers end at
//! `i64` (a seed of 2⁶³ or more was refused from a dict although the same scenario's JSON file
//! ran) and JSON has no infinity (MATLAB's default `MeasurementRange` is `inf`). Each value
//! reaches serde as its own kind: integers as integers (of up to 128 bits; the target type says
//! what it takes), numbers as `f64`, text as text, lists as sequences, tables as maps, `Null` as
//! an absent option or a unit. Errors name the key path where they happened (the
//! `serde_path_to_error` crate follows the path), e.g. `imu.seed` or `trajectory.position_m[1]`.
use std::fmt;

use serde::Deserialize;
use serde::de::value::{MapDeserializer, SeqDeserializer};
use serde::de::{self, IntoDeserializer, Visitor};

use crate::params::ParamValue;

/// Why a tree does not fit the type asked for: serde's message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TreeError(String);

impl fmt::Display for TreeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for TreeError {}

impl de::Error for TreeError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self(msg.to_string())
    }
}

/// Where a tree does not fit: the key path (`imu.seed`, `trajectory.position_m[1]`; empty at
/// the top) and serde's message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TreeMismatch {
    /// Dotted key path, list items as `[k]`; the part serde can follow (a value read through an
    /// internally tagged or untagged enum is named by the enum's key).
    pub path: String,
    /// What does not fit.
    pub message: String,
}

/// `tree` read as a `T`.
///
/// # Errors
/// [`TreeMismatch`] naming the key whose value does not fit, and why.
pub fn read<T: for<'de> Deserialize<'de>>(tree: &ParamValue) -> Result<T, TreeMismatch> {
    serde_path_to_error::deserialize(tree).map_err(|e| TreeMismatch {
        path: key_path(e.path()),
        message: e.into_inner().0,
    })
}

/// `path` as a dotted key path, list items as `[k]` (`trajectory.position_m[1]`), cut at the
/// first segment the tracker could not follow ("?", after a buffered enum), so that it names the
/// key that holds the value.
#[must_use]
pub fn key_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    path.iter()
        .take_while(|s| !matches!(s, Segment::Unknown))
        .fold(String::new(), |mut path, s| {
            match s {
                Segment::Seq { index } => path.push_str(&format!("[{index}]")),
                Segment::Map { key } | Segment::Enum { variant: key } => {
                    if !path.is_empty() {
                        path.push('.');
                    }
                    path.push_str(key);
                }
                Segment::Unknown => {}
            }
            path
        })
}

impl<'de> IntoDeserializer<'de, TreeError> for &'de ParamValue {
    type Deserializer = Self;
    fn into_deserializer(self) -> Self {
        self
    }
}

impl<'de> de::Deserializer<'de> for &'de ParamValue {
    type Error = TreeError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, TreeError> {
        match self {
            ParamValue::Bool(b) => visitor.visit_bool(*b),
            ParamValue::Integer(i) => {
                if let Ok(v) = i64::try_from(*i) {
                    visitor.visit_i64(v)
                } else if let Ok(v) = u64::try_from(*i) {
                    visitor.visit_u64(v)
                } else {
                    visitor.visit_i128(*i)
                }
            }
            ParamValue::Number(x) => visitor.visit_f64(*x),
            ParamValue::Text(s) => visitor.visit_borrowed_str(s),
            ParamValue::List(items) => {
                let mut seq = SeqDeserializer::new(items.iter());
                let value = visitor.visit_seq(&mut seq)?;
                seq.end()?;
                Ok(value)
            }
            ParamValue::Table(table) => {
                let mut map = MapDeserializer::new(table.iter().map(|(k, v)| (k.as_str(), v)));
                let value = visitor.visit_map(&mut map)?;
                map.end()?;
                Ok(value)
            }
            ParamValue::Null => visitor.visit_unit(),
        }
    }

    /// `Null` is an absent value; anything else is present.
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, TreeError> {
        match self {
            ParamValue::Null => visitor.visit_none(),
            _ => visitor.visit_some(self),
        }
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, TreeError> {
        visitor.visit_newtype_struct(self)
    }

    /// A unit variant by its name (`"NED"`), or a table of one key, the variant, holding its
    /// content (`{ file = "t.csv" }`), as TOML and JSON write enums.
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, TreeError> {
        match self {
            ParamValue::Text(s) => visitor.visit_enum(s.as_str().into_deserializer()),
            ParamValue::Table(table) => match table.iter().next() {
                Some((variant, value)) if table.len() == 1 => visitor.visit_enum(Variant {
                    variant: variant.as_str(),
                    value,
                }),
                _ => Err(de::Error::invalid_length(
                    table.len(),
                    &"a table of one key, the variant",
                )),
            },
            other => Err(de::Error::invalid_type(unexpected(other), &visitor)),
        }
    }

    /// A table's keys that are among `fields` first, in the order of `fields`, then the others
    /// (which the type may refuse), so that a type that must read one key before the rest (a
    /// trajectory's `type`) reads it first from a tree, whose tables keep their keys sorted.
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, TreeError> {
        let ParamValue::Table(table) = self else {
            return self.deserialize_any(visitor);
        };
        let named = fields.iter().filter_map(|f| table.get_key_value(*f));
        let others = table.iter().filter(|(k, _)| !fields.contains(&k.as_str()));
        let mut map = MapDeserializer::new(named.chain(others).map(|(k, v)| (k.as_str(), v)));
        let value = visitor.visit_map(&mut map)?;
        map.end()?;
        Ok(value)
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        unit unit_struct seq tuple tuple_struct map identifier ignored_any
    }
}

/// The value's kind as serde names it in messages.
fn unexpected(value: &ParamValue) -> de::Unexpected<'_> {
    match value {
        ParamValue::Bool(b) => de::Unexpected::Bool(*b),
        ParamValue::Integer(i) => i64::try_from(*i).map_or_else(
            |_| {
                u64::try_from(*i).map_or(de::Unexpected::Other("integer"), de::Unexpected::Unsigned)
            },
            de::Unexpected::Signed,
        ),
        ParamValue::Number(x) => de::Unexpected::Float(*x),
        ParamValue::Text(s) => de::Unexpected::Str(s),
        ParamValue::List(_) => de::Unexpected::Seq,
        ParamValue::Table(_) => de::Unexpected::Map,
        ParamValue::Null => de::Unexpected::Unit,
    }
}

/// An enum written as a one-entry table: the variant's name and its content.
struct Variant<'de> {
    variant: &'de str,
    value: &'de ParamValue,
}

impl<'de> de::EnumAccess<'de> for Variant<'de> {
    type Error = TreeError;
    type Variant = &'de ParamValue;

    fn variant_seed<S: de::DeserializeSeed<'de>>(
        self,
        seed: S,
    ) -> Result<(S::Value, Self::Variant), TreeError> {
        let name: de::value::BorrowedStrDeserializer<'de, TreeError> =
            de::value::BorrowedStrDeserializer::new(self.variant);
        Ok((seed.deserialize(name)?, self.value))
    }
}

impl<'de> de::VariantAccess<'de> for &'de ParamValue {
    type Error = TreeError;

    fn unit_variant(self) -> Result<(), TreeError> {
        de::Deserialize::deserialize(self)
    }

    fn newtype_variant_seed<S: de::DeserializeSeed<'de>>(
        self,
        seed: S,
    ) -> Result<S::Value, TreeError> {
        seed.deserialize(self)
    }

    fn tuple_variant<V: Visitor<'de>>(
        self,
        _len: usize,
        visitor: V,
    ) -> Result<V::Value, TreeError> {
        de::Deserializer::deserialize_seq(self, visitor)
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, TreeError> {
        de::Deserializer::deserialize_map(self, visitor)
    }
}
