//! Mutations of input files: byte edits, number tokens replaced by boundary values, lines
//! spliced in from other files of the corpus or from a list of telling lines.

use super::rng::Rng;

/// Numbers at the edges: zero and signs, 2³¹/2³²/2⁵³/2⁶³/2⁶⁴ and their neighbours, beyond f64,
/// not numbers at all.
pub const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "0.5",
    "-0.5",
    "1e-300",
    "1e-9",
    "1e9",
    "1e15",
    "1e19",
    "3e19",
    "1e150",
    "1e200",
    "1e300",
    "1e308",
    "-1e308",
    "1e400",
    "-1e400",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "5000000000",
    "9007199254740993",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999",
    "0x10",
    "1,5",
    "",
];

/// Lines that steer a file towards rarely taken paths of the readers.
const LINES: &[&str] = &[
    "DIMENSION: 5000000000",
    "DIMENSION : 4294967296",
    "DIMENSION: 3",
    "TYPE: ATSP",
    "TYPE: SOP",
    "TYPE: GTSP",
    "TYPE: PCGLNS",
    "TYPE: TOUR",
    "EDGE_WEIGHT_TYPE: EXPLICIT",
    "EDGE_WEIGHT_TYPE: EUC_2D",
    "EDGE_WEIGHT_TYPE: GEO",
    "EDGE_WEIGHT_FORMAT: FULL_MATRIX",
    "EDGE_WEIGHT_FORMAT: LOWER_DIAG_ROW",
    "EDGE_WEIGHT_SECTION",
    "NODE_COORD_SECTION",
    "FIXED_EDGES_SECTION",
    "1 3",
    "-1",
    "GTSP_SETS: 88888888888",
    "GTSP_SET_SECTION",
    "GTSP_SET_ORDERING",
    "START_GROUP_SECTION",
    "EOF",
    "1 3e19 0",
    "2 1e308 -1e308",
    "solid \u{00e4}\u{00f6}",
    "facet normal 0 0 1",
    "outer loop",
    "vertex 0 0 0",
    "vertex 1e39 0 0",
    "endloop",
    "endfacet",
    "endsolid",
    "element vertex 4000000000",
    "element face 3",
    "property list uchar int vertex_indices",
    "end_header",
    "v 0 0 0",
    "f 1 2 3",
    "f 1 2 99999999",
    "G0 X0 Y0",
    "G1 X1e300 Y0 F1000",
    "M20",
    "M21",
    "M8",
    "M9",
    "G4 P5000",
    "(comment",
    "\r",
    "[1,2,3]",
    "{\"a\": 0, \"b\": 4294967296, \"required\": true}",
];

/// A mutated copy of `data`; `other` (another file of the same kind) may be spliced in.
pub fn mutate(rng: &mut Rng, data: &[u8], other: &[u8]) -> Vec<u8> {
    let mut out = data.to_vec();
    for _ in 0..rng.range(1, 5) {
        match rng.range(0, 10) {
            0 => flip(rng, &mut out),
            1 => insert_bytes(rng, &mut out),
            2 => delete(rng, &mut out),
            3 => duplicate(rng, &mut out),
            4..=6 => replace_number(rng, &mut out),
            7 => splice(rng, &mut out, other),
            8 => insert_line(rng, &mut out),
            _ => truncate(rng, &mut out),
        }
    }
    out
}

fn flip(rng: &mut Rng, v: &mut [u8]) {
    if !v.is_empty() {
        let k = rng.range(0, v.len());
        v[k] = rng.byte();
    }
}

fn insert_bytes(rng: &mut Rng, v: &mut Vec<u8>) {
    const ALPHABET: &[u8] = b"0123456789 \n\t-+.eE{}[],\":;()XYZGMN/\\\x00\xff";
    let k = rng.range(0, v.len() + 1);
    let n = rng.range(1, 8);
    let bytes: Vec<u8> = (0..n).map(|_| *rng.pick(ALPHABET).unwrap_or(&b' ')).collect();
    v.splice(k..k, bytes);
}

fn delete(rng: &mut Rng, v: &mut Vec<u8>) {
    if !v.is_empty() {
        let a = rng.range(0, v.len());
        let b = (a + rng.range(1, 64)).min(v.len());
        v.drain(a..b);
    }
}

fn duplicate(rng: &mut Rng, v: &mut Vec<u8>) {
    if !v.is_empty() && v.len() < 1 << 20 {
        let a = rng.range(0, v.len());
        let b = (a + rng.range(1, 256)).min(v.len());
        let chunk = v[a..b].to_vec();
        let at = rng.range(0, v.len() + 1);
        v.splice(at..at, chunk);
    }
}

fn truncate(rng: &mut Rng, v: &mut Vec<u8>) {
    if !v.is_empty() {
        let k = rng.range(0, v.len());
        v.truncate(k);
    }
}

/// Replaces one number-like token (digits, sign, point, exponent) by a boundary value.
fn replace_number(rng: &mut Rng, v: &mut Vec<u8>) {
    let numeric = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E');
    let starts: Vec<usize> =
        (0..v.len()).filter(|&i| v[i].is_ascii_digit() && (i == 0 || !numeric(v[i - 1]))).collect();
    let Some(&a) = rng.pick(&starts) else { return };
    let mut a = a;
    if a > 0 && v[a - 1] == b'-' {
        a -= 1;
    }
    let mut b = a + 1;
    while b < v.len() && numeric(v[b]) {
        b += 1;
    }
    let with = rng.pick(NUMBERS).unwrap_or(&"0").as_bytes().to_vec();
    v.splice(a..b, with);
}

/// Inserts a few lines of `other` at a line start of `v`.
fn splice(rng: &mut Rng, v: &mut Vec<u8>, other: &[u8]) {
    let lines: Vec<&[u8]> = other.split(|&b| b == b'\n').collect();
    if lines.is_empty() {
        return;
    }
    let a = rng.range(0, lines.len());
    let b = (a + rng.range(1, 8)).min(lines.len());
    let mut chunk = lines[a..b].join(&b'\n');
    chunk.push(b'\n');
    let at = line_start(rng, v);
    v.splice(at..at, chunk);
}

fn insert_line(rng: &mut Rng, v: &mut Vec<u8>) {
    let mut line = rng.pick(LINES).unwrap_or(&"EOF").as_bytes().to_vec();
    line.push(b'\n');
    let at = line_start(rng, v);
    v.splice(at..at, line);
}

fn line_start(rng: &mut Rng, v: &[u8]) -> usize {
    let starts: Vec<usize> = std::iter::once(0).chain((0..v.len()).filter(|&i| v[i] == b'\n').map(|i| i + 1)).collect();
    *rng.pick(&starts).unwrap_or(&0)
}
