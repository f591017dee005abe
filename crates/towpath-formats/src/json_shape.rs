//! The JSON problem format's objects are objects: serde's derived readers also take a struct
//! written as an array of its fields in order (`[1, 2, 3]` read as a problem whose `name` is
//! `1`, refused with "expected a string"). [`MapOnly`] lets a struct be read from a JSON object
//! only, so an array is refused as what it is; [`friendly`] rewords serde's type errors in the
//! format's terms.

use serde::de::{Deserializer, Visitor};

/// A deserializer that reads structs from maps (JSON objects) only; everything else is passed
/// through. Used by the format's hand-written `Deserialize` impls (see `json.rs`).
pub(crate) struct MapOnly<D>(pub D);

impl<'de, D: Deserializer<'de>> Deserializer<'de> for MapOnly<D> {
    type Error = D::Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Self::Error> {
        self.0.deserialize_any(visitor)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Self::Error> {
        self.0.deserialize_map(visitor)
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option unit
        unit_struct newtype_struct seq tuple tuple_struct map enum identifier ignored_any
    }
}

/// serde_json's "invalid type: X, expected Y" as "expected Y, found X", in the format's words
/// (objects and arrays, the format's object names).
pub(crate) fn friendly(msg: &str) -> String {
    let words = |s: &str| {
        s.replace("struct JsonProblem", "a problem object {\"states\": …, \"tasks\": […]}")
            .replace("struct JsonStates", "a states object {\"points\": […]} or {\"matrix\": […]}")
            .replace("struct JsonTask", "a task object {\"id\": …, \"modes\": […]}")
            .replace("struct JsonMode", "a mode object {\"entry\": …}")
            .replace("a sequence", "an array")
            .replace("sequence", "an array")
            .replace("map", "an object")
    };
    if let Some(rest) = msg.strip_prefix("invalid type: ") {
        if let Some((found, expected)) = rest.split_once(", expected ") {
            return format!("expected {}, found {}", words(expected), words(found));
        }
    }
    msg.to_string()
}
