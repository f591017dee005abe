//! Binary responses of typed arrays, read by the front end without any parsing.
//!
//! Layout (little-endian): the 4 bytes `TPB1`, a `u32` length of a JSON header, the header
//! (UTF-8, padded with spaces to a multiple of 4), then the arrays, each starting at a multiple
//! of 4 bytes from the start of the data. The header is
//! `{"arrays": [{"name", "type", "offset", "length"}], ...}` with `type` one of `f32`, `u32`,
//! `i32`, `u8`, offsets counted from the first byte after the header, `length` in elements.

use serde_json::{json, Value};

/// Typed arrays and a header, to be sent as one binary body.
#[derive(Default, Debug, Clone)]
pub struct Blob {
    arrays: Vec<Value>,
    data: Vec<u8>,
    extra: serde_json::Map<String, Value>,
}

impl Blob {
    /// An empty blob.
    pub fn new() -> Blob {
        Blob::default()
    }

    fn push(&mut self, name: &str, ty: &str, length: usize, bytes: impl Iterator<Item = u8>) {
        while self.data.len() % 4 != 0 {
            self.data.push(0);
        }
        let offset = self.data.len();
        self.data.extend(bytes);
        self.arrays.push(json!({"name": name, "type": ty, "offset": offset, "length": length}));
    }

    /// Adds an `f32` array.
    pub fn f32(&mut self, name: &str, v: &[f32]) {
        self.push(name, "f32", v.len(), v.iter().flat_map(|x| x.to_le_bytes()));
    }

    /// Adds a `u32` array.
    pub fn u32(&mut self, name: &str, v: &[u32]) {
        self.push(name, "u32", v.len(), v.iter().flat_map(|x| x.to_le_bytes()));
    }

    /// Adds an `i32` array.
    pub fn i32(&mut self, name: &str, v: &[i32]) {
        self.push(name, "i32", v.len(), v.iter().flat_map(|x| x.to_le_bytes()));
    }

    /// Adds a `u8` array.
    pub fn u8(&mut self, name: &str, v: &[u8]) {
        self.push(name, "u8", v.len(), v.iter().copied());
    }

    /// Adds a header field.
    pub fn meta(&mut self, key: &str, value: Value) {
        self.extra.insert(key.to_string(), value);
    }

    /// The bytes to send.
    pub fn encode(&self) -> Vec<u8> {
        let mut header = self.extra.clone();
        header.insert("arrays".into(), Value::Array(self.arrays.clone()));
        let mut h = Value::Object(header).to_string().into_bytes();
        while h.len() % 4 != 0 {
            h.push(b' ');
        }
        let mut out = Vec::with_capacity(8 + h.len() + self.data.len());
        out.extend_from_slice(b"TPB1");
        out.extend_from_slice(&(h.len() as u32).to_le_bytes());
        out.extend_from_slice(&h);
        out.extend_from_slice(&self.data);
        out
    }
}

/// Reads a blob back (for tests and tools): the header and the data bytes.
pub fn decode(bytes: &[u8]) -> Option<(Value, &[u8])> {
    if bytes.len() < 8 || &bytes[..4] != b"TPB1" {
        return None;
    }
    let n = u32::from_le_bytes(bytes[4..8].try_into().ok()?) as usize;
    let header = serde_json::from_slice(bytes.get(8..8 + n)?).ok()?;
    Some((header, bytes.get(8 + n..)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_are_aligned_and_read_back() {
        let mut b = Blob::new();
        b.u8("k", &[1, 2, 3]);
        b.f32("p", &[1.5, -2.0]);
        b.meta("name", json!("x"));
        let bytes = b.encode();
        let (h, data) = decode(&bytes).expect("decodes");
        assert_eq!(h["name"], "x");
        let arrays = h["arrays"].as_array().expect("arrays");
        let p = &arrays[1];
        let off = p["offset"].as_u64().expect("offset") as usize;
        assert_eq!(off % 4, 0);
        assert_eq!((8 + bytes.len() - data.len() + off) % 4, 0, "absolute offset aligned");
        let v = f32::from_le_bytes(data[off + 4..off + 8].try_into().expect("4 bytes"));
        assert_eq!(v, -2.0);
    }
}
