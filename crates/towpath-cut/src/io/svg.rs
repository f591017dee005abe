//! SVG in and out.
//!
//! **Reading.** The document is parsed by `usvg`, which applies transforms, resolves groups,
//! styles and `use`, and turns every shape (rect, circle, ellipse, line, polyline, polygon,
//! path with arcs and quadratic curves) into lines and cubic Béziers; every subpath of a shape
//! is one piece (closed when it ends with `Z`). Coordinates are taken back to the root's user
//! units (the `viewBox`), so lengths are in the drawing's units. Each top-level `<g>` (an
//! Inkscape layer, say) is an operation, in document order; shapes outside any group form an
//! operation of their own. `usvg` works in 32-bit floats: coordinates keep about 7 significant
//! digits. Text is not converted (convert it to paths first).
//!
//! **Writing.** The document is written back around the pieces: everything before the root's
//! start tag and the start tag itself, top-level elements that hold no piece (defs, metadata,
//! text, ...) and each layer's start tag are copied as they were; inside its layer, the
//! non-shape content comes first, as it was, then the layer's pieces in their new order, each a
//! `<path>` with its element's attributes (and the presentation attributes of the groups between
//! it and the layer) in the layer's own coordinates. A shape of several subpaths becomes one
//! `<path>` per subpath (the id suffixed `-2`, `-3`, ... after the first).

use std::collections::HashMap;

use crate::error::CutError;
use crate::geom::{seg_flatten, Path, Seg, P2};
use crate::model::{Drawing, Piece, Placement};

const SHAPES: [&str; 7] = ["path", "rect", "circle", "ellipse", "line", "polyline", "polygon"];
const SKIP: [&str; 7] = ["defs", "clipPath", "mask", "pattern", "marker", "symbol", "style"];
const GEOMETRY_ATTRS: [&str; 16] =
    ["d", "x", "y", "width", "height", "rx", "ry", "cx", "cy", "r", "x1", "y1", "x2", "y2", "points", "transform"];
const INHERITED: [&str; 12] = [
    "fill",
    "stroke",
    "stroke-width",
    "stroke-linecap",
    "stroke-linejoin",
    "stroke-dasharray",
    "stroke-opacity",
    "fill-opacity",
    "opacity",
    "style",
    "class",
    "fill-rule",
];

/// A 2D affine map `[a, b, c, d, e, f]`: (x, y) → (a x + c y + e, b x + d y + f).
type Affine = [f64; 6];

fn compose(m: Affine, n: Affine) -> Affine {
    // m ∘ n
    [
        m[0] * n[0] + m[2] * n[1],
        m[1] * n[0] + m[3] * n[1],
        m[0] * n[2] + m[2] * n[3],
        m[1] * n[2] + m[3] * n[3],
        m[0] * n[4] + m[2] * n[5] + m[4],
        m[1] * n[4] + m[3] * n[5] + m[5],
    ]
}

fn invert(m: Affine) -> Option<Affine> {
    let det = m[0] * m[3] - m[1] * m[2];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (a, b, c, d) = (m[3] / det, -m[1] / det, -m[2] / det, m[0] / det);
    Some([a, b, c, d, -(a * m[4] + c * m[5]), -(b * m[4] + d * m[5])])
}

fn apply(m: &Affine, p: P2) -> P2 {
    [m[0] * p[0] + m[2] * p[1] + m[4], m[1] * p[0] + m[3] * p[1] + m[5]]
}

const IDENTITY: Affine = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0];

/// One shape element of the source.
#[derive(Clone, Debug)]
struct Element {
    /// Byte range of the element in the source.
    range: std::ops::Range<usize>,
    /// Attributes to write on its pieces (raw `name="value"` text).
    attrs: String,
    /// Its own id, if it had one.
    id: Option<String>,
    /// Its layer (top-level child index) or `None` at the root.
    layer: Option<usize>,
    /// How many pieces it gave.
    pieces: usize,
}

/// What the SVG writer keeps of the input.
#[derive(Clone, Debug)]
pub struct SvgSource {
    text: String,
    /// End of the root start tag.
    root_open_end: usize,
    /// Start of the root end tag.
    root_close_start: usize,
    /// Top-level children: byte range, whether it is a layer holding pieces.
    top: Vec<(std::ops::Range<usize>, bool)>,
    /// Layer transforms (user units → layer's own), by top-level index.
    layer_inverse: HashMap<usize, Affine>,
    /// For layers: raw text ranges of the non-piece content to copy.
    layer_keep: HashMap<usize, Vec<std::ops::Range<usize>>>,
    /// Byte range of each layer's start tag.
    layer_open: HashMap<usize, std::ops::Range<usize>>,
    elements: Vec<Element>,
    /// For each piece: its element and subpath number.
    piece_element: Vec<(usize, usize)>,
    /// Operation of each layer (top-level index) and of root-level shapes.
    op_layer: Vec<Option<usize>>,
    tol: f64,
}

/// "line N" of a byte offset, from the offsets of the line starts.
fn line_of(line_starts: &[usize], at: usize) -> String {
    format!("line {}", line_starts.partition_point(|&s| s <= at))
}

/// The start tag's raw text range of a node.
fn start_tag(text: &str, node: roxmltree::Node) -> std::ops::Range<usize> {
    let s = node.range().start;
    let bytes = text.as_bytes();
    let mut quote = 0u8;
    let mut i = s;
    while i < node.range().end {
        let b = bytes[i];
        if quote != 0 {
            if b == quote {
                quote = 0;
            }
        } else if b == b'"' || b == b'\'' {
            quote = b;
        } else if b == b'>' {
            return s..i + 1;
        }
        i += 1;
    }
    s..node.range().end
}

fn qualified(node: roxmltree::Node, a: &roxmltree::Attribute) -> String {
    match a.namespace().and_then(|ns| node.lookup_prefix(ns)) {
        Some(p) if !p.is_empty() => format!("{p}:{}", a.name()),
        _ => a.name().to_string(),
    }
}

fn escape(v: &str) -> String {
    v.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;")
}

fn parse_transform(v: Option<&str>) -> Affine {
    match v.and_then(|s| s.parse::<svgtypes::Transform>().ok()) {
        Some(t) => [t.a, t.b, t.c, t.d, t.e, t.f],
        None => IDENTITY,
    }
}

/// The root's user units → canvas map (viewBox, default `xMidYMid meet`).
fn root_map(root: roxmltree::Node, size: (f64, f64)) -> Affine {
    let vb: Vec<f64> = root
        .attribute("viewBox")
        .map(|v| {
            v.split(|c: char| c == ',' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .filter_map(|s| s.parse().ok())
                .collect()
        })
        .unwrap_or_default();
    if vb.len() != 4 || vb[2] <= 0.0 || vb[3] <= 0.0 {
        return IDENTITY;
    }
    let (sx, sy) = (size.0 / vb[2], size.1 / vb[3]);
    let none = root.attribute("preserveAspectRatio").is_some_and(|p| p.trim_start().starts_with("none"));
    if none {
        return [sx, 0.0, 0.0, sy, -vb[0] * sx, -vb[1] * sy];
    }
    let s = sx.min(sy);
    [s, 0.0, 0.0, s, -vb[0] * s + (size.0 - vb[2] * s) / 2.0, -vb[1] * s + (size.1 - vb[3] * s) / 2.0]
}

/// Reads an SVG document.
pub fn read(text: &str, name: &str, tol: f64) -> Result<(Drawing, SvgSource), CutError> {
    let opt = roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() };
    let doc = roxmltree::Document::parse_with_options(text, opt)
        .map_err(|e| CutError::Input(format!("{name}:{}:{}: {e}", e.pos().row, e.pos().col)))?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(CutError::Input(format!("{name}: the root element is <{}>, not <svg>", root.tag_name().name())));
    }
    // Shape elements in document order, each tagged with a synthetic id for usvg.
    let top: Vec<roxmltree::Node> = root.children().filter(|n| n.is_element()).collect();
    let top_index: HashMap<roxmltree::NodeId, usize> = top.iter().enumerate().map(|(i, n)| (n.id(), i)).collect();
    let mut elements = Vec::new();
    let mut inserts: Vec<(usize, usize, String)> = Vec::new();
    let mut by_tag: HashMap<String, usize> = HashMap::new();
    for node in root.descendants().filter(|n| n.is_element()) {
        if !SHAPES.contains(&node.tag_name().name()) {
            continue;
        }
        if node.ancestors().any(|a| SKIP.contains(&a.tag_name().name())) {
            continue;
        }
        let layer =
            node.ancestors().skip(1).find(|a| a.parent() == Some(root)).and_then(|a| top_index.get(&a.id()).copied());
        let k = elements.len();
        let tag = format!("towpath-{k}");
        // Insert the synthetic id right after "<name"; an existing id is renamed by usvg's view only.
        let st = start_tag(text, node);
        let raw = &text[st.clone()];
        let name_len = raw[1..].find(|c: char| c.is_whitespace() || c == '/' || c == '>').unwrap_or(raw.len() - 1);
        let mut attrs = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for a in node.attributes() {
            let q = qualified(node, &a);
            if GEOMETRY_ATTRS.contains(&a.name()) || q == "id" {
                continue;
            }
            seen.insert(q.clone());
            attrs.push(format!("{q}=\"{}\"", escape(a.value())));
        }
        // Presentation attributes of the groups between the layer and the element.
        for anc in node.ancestors().skip(1) {
            if anc == root || layer.is_some_and(|l| top[l] == anc) {
                break;
            }
            for a in anc.attributes() {
                let q = qualified(anc, &a);
                if INHERITED.contains(&a.name()) && seen.insert(q.clone()) {
                    attrs.push(format!("{q}=\"{}\"", escape(a.value())));
                }
            }
        }
        let id = node.attribute("id").map(|s| s.to_string());
        by_tag.insert(tag.clone(), k);
        inserts.push((st.start + 1 + name_len, st.end, tag));
        elements.push(Element { range: node.range(), attrs: attrs.join(" "), id, layer, pieces: 0 });
    }
    // Build the tagged text: each shape gets our id; an id it had is renamed out of the way.
    let mut tagged = String::with_capacity(text.len() + inserts.len() * 24);
    let mut last = 0;
    for (k, (at, end, tag)) in inserts.iter().enumerate() {
        tagged.push_str(&text[last..*at]);
        tagged.push_str(&format!(" id=\"{tag}\""));
        if elements[k].id.is_some() {
            tagged.push_str(&rename_id_attr(&text[*at..*end]));
            last = *end;
        } else {
            last = *at;
        }
    }
    tagged.push_str(&text[last..]);
    let tree = usvg::Tree::from_str(&tagged, &usvg::Options::default())
        .map_err(|e| CutError::Input(format!("{name}: {e}")))?;
    let size = tree.size();
    let to_user = invert(root_map(root, (size.width() as f64, size.height() as f64))).unwrap_or(IDENTITY);
    // Operations: layers in document order, then root-level shapes.
    let mut drawing = Drawing::default();
    let mut op_layer: Vec<Option<usize>> = Vec::new();
    let mut layer_op: HashMap<Option<usize>, usize> = HashMap::new();
    for e in &elements {
        if let std::collections::hash_map::Entry::Vacant(slot) = layer_op.entry(e.layer) {
            let label = match e.layer {
                Some(l) => {
                    let n = top[l];
                    n.attribute(("http://www.inkscape.org/namespaces/inkscape", "label"))
                        .or(n.attribute("id"))
                        .map_or(format!("layer {}", l + 1), |s| s.to_string())
                }
                None => "(root)".to_string(),
            };
            slot.insert(op_layer.len());
            op_layer.push(e.layer);
            drawing.operations.push(label);
        }
    }
    let line_starts: Vec<usize> = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
    let mut piece_element = Vec::new();
    let mut paths: Vec<(usize, Vec<Path>)> = Vec::new();
    collect(tree.root(), &by_tag, &to_user, &mut paths);
    paths.sort_by_key(|(k, _)| *k);
    for (k, subpaths) in paths {
        let e = &mut elements[k];
        if e.pieces > 0 {
            continue;
        }
        e.pieces = subpaths.len();
        let base =
            e.id.clone().unwrap_or_else(|| format!("{} element {}", line_of(&line_starts, e.range.start), k + 1));
        for (j, path) in subpaths.into_iter().enumerate() {
            let id = if j == 0 { base.clone() } else { format!("{base}-{}", j + 1) };
            piece_element.push((k, j));
            drawing.pieces.push(Piece { id, operation: layer_op[&e.layer], path, reversible: true, fixed: false });
        }
    }
    // Layer start tags, transforms, and content to keep.
    let mut layer_inverse = HashMap::new();
    let mut layer_keep = HashMap::new();
    let mut layer_open = HashMap::new();
    let mut piece_ranges: Vec<std::ops::Range<usize>> =
        elements.iter().filter(|e| e.pieces > 0).map(|e| e.range.clone()).collect();
    piece_ranges.sort_by_key(|r| r.start);
    let mut top_out = Vec::new();
    let holding: std::collections::HashSet<usize> =
        elements.iter().filter(|e| e.pieces > 0).filter_map(|e| e.layer).collect();
    for (l, node) in top.iter().enumerate() {
        let holds = holding.contains(&l);
        top_out.push((node.range(), holds));
        if holds {
            let t = parse_transform(node.attribute("transform"));
            layer_inverse.insert(l, invert(t).unwrap_or(IDENTITY));
            layer_open.insert(l, start_tag(text, *node));
            let mut keep = Vec::new();
            keep_content(*node, &piece_ranges, &mut keep);
            layer_keep.insert(l, keep);
        }
    }
    // Root-level shapes that became pieces are dropped from `top` by the writer.
    let root_open_end = start_tag(text, root).end;
    let root_close_start = text[..root.range().end].rfind("</").unwrap_or(root.range().end);
    let source = SvgSource {
        text: text.to_string(),
        root_open_end,
        root_close_start: root_close_start.max(root_open_end),
        top: top_out,
        layer_inverse,
        layer_keep,
        layer_open,
        elements,
        piece_element,
        op_layer,
        tol,
    };
    Ok((drawing, source))
}

/// The start tag text with its first `id=` attribute renamed `data-towpath-id=`.
fn rename_id_attr(seg: &str) -> String {
    let mut quote: Option<char> = None;
    let mut out = String::with_capacity(seg.len() + 16);
    let mut it = seg.char_indices().peekable();
    let mut done = false;
    while let Some((i, c)) = it.next() {
        if let Some(q) = quote {
            if c == q {
                quote = None;
            }
        } else if c == '"' || c == '\'' {
            quote = Some(c);
        } else if !done && c.is_whitespace() {
            let rest = seg[i + c.len_utf8()..].trim_start();
            if rest.starts_with("id") && rest[2..].trim_start().starts_with('=') {
                out.push_str(" data-towpath-id");
                let skip_to = seg.len() - rest.len() + 2;
                while it.peek().is_some_and(|(j, _)| *j < skip_to) {
                    it.next();
                }
                done = true;
                continue;
            }
        }
        out.push(c);
    }
    out
}

/// Ranges of a layer's content that hold no piece (copied as they were); `pieces` sorted by start.
fn keep_content(node: roxmltree::Node, pieces: &[std::ops::Range<usize>], out: &mut Vec<std::ops::Range<usize>>) {
    for child in node.children() {
        let r = child.range();
        let k = pieces.partition_point(|p| p.start < r.start);
        let holds = pieces.get(k).is_some_and(|p| p.end <= r.end);
        if !holds {
            if child.is_element() || child.is_comment() {
                out.push(r);
            }
        } else if child.is_element() && pieces.get(k) != Some(&r) {
            keep_content(child, pieces, out);
        }
    }
}

fn collect(group: &usvg::Group, by_tag: &HashMap<String, usize>, to_user: &Affine, out: &mut Vec<(usize, Vec<Path>)>) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect(g, by_tag, to_user, out),
            usvg::Node::Path(p) => {
                let Some(&k) = by_tag.get(p.id()) else { continue };
                let t = p.abs_transform();
                let abs: Affine = [t.sx as f64, t.ky as f64, t.kx as f64, t.sy as f64, t.tx as f64, t.ty as f64];
                let m = compose(*to_user, abs);
                out.push((k, subpaths(p.data(), &m)));
            }
            _ => {}
        }
    }
}

fn subpaths(data: &usvg::tiny_skia_path::Path, m: &Affine) -> Vec<Path> {
    use usvg::tiny_skia_path::PathSegment as S;
    let pt = |p: usvg::tiny_skia_path::Point| apply(m, [p.x as f64, p.y as f64]);
    let mut out = Vec::new();
    let mut cur: Option<Path> = None;
    let mut at = [0.0, 0.0];
    let flush = |cur: &mut Option<Path>, out: &mut Vec<Path>| {
        if let Some(p) = cur.take() {
            if !p.segs.is_empty() {
                out.push(p);
            }
        }
    };
    for seg in data.segments() {
        match seg {
            S::MoveTo(p) => {
                flush(&mut cur, &mut out);
                at = pt(p);
                cur = Some(Path { start: at, segs: Vec::new(), closed: false });
            }
            S::LineTo(p) => {
                at = pt(p);
                cur.get_or_insert(Path { start: at, segs: Vec::new(), closed: false }).segs.push(Seg::Line(at));
            }
            S::QuadTo(q, p) => {
                let (q, p) = (pt(q), pt(p));
                let c1 = [at[0] + 2.0 / 3.0 * (q[0] - at[0]), at[1] + 2.0 / 3.0 * (q[1] - at[1])];
                let c2 = [p[0] + 2.0 / 3.0 * (q[0] - p[0]), p[1] + 2.0 / 3.0 * (q[1] - p[1])];
                cur.get_or_insert(Path { start: at, segs: Vec::new(), closed: false }).segs.push(Seg::Cubic {
                    c1,
                    c2,
                    to: p,
                });
                at = p;
            }
            S::CubicTo(c1, c2, p) => {
                let (c1, c2, p) = (pt(c1), pt(c2), pt(p));
                cur.get_or_insert(Path { start: at, segs: Vec::new(), closed: false }).segs.push(Seg::Cubic {
                    c1,
                    c2,
                    to: p,
                });
                at = p;
            }
            S::Close => {
                if let Some(mut p) = cur.take() {
                    if p.end() != p.start {
                        p.segs.push(Seg::Line(p.start));
                    }
                    p.closed = !p.segs.is_empty();
                    at = p.start;
                    if !p.segs.is_empty() {
                        out.push(p);
                    }
                }
            }
        }
    }
    flush(&mut cur, &mut out);
    out
}

/// Appends a command letter and coordinates to path data, without a string per number.
fn push_cmd(d: &mut String, cmd: char, pts: &[P2]) {
    use std::fmt::Write;
    d.push(cmd);
    for (k, q) in pts.iter().enumerate() {
        let (x, y) = (if q[0] == 0.0 { 0.0 } else { q[0] }, if q[1] == 0.0 { 0.0 } else { q[1] });
        // writing to a String cannot fail
        let _ = if k == 0 { write!(d, "{x} {y}") } else { write!(d, " {x} {y}") };
    }
}

/// SVG path data of a path under `m` (arcs flattened within `tol`).
fn path_data(path: &Path, m: &Affine, tol: f64) -> String {
    let mut d = String::new();
    let p = apply(m, path.start);
    push_cmd(&mut d, 'M', &[p]);
    let mut prev = path.start;
    let n = path.segs.len();
    for (i, s) in path.segs.iter().enumerate() {
        if path.closed && i + 1 == n {
            if let Seg::Line(_) = s {
                d.push('Z');
                break;
            }
        }
        match *s {
            Seg::Line(q) => {
                push_cmd(&mut d, 'L', &[apply(m, q)]);
            }
            Seg::Cubic { c1, c2, to } => {
                push_cmd(&mut d, 'C', &[apply(m, c1), apply(m, c2), apply(m, to)]);
            }
            Seg::Arc { .. } => {
                let mut f = Vec::new();
                seg_flatten(prev, s, tol, &mut f);
                for q in f {
                    push_cmd(&mut d, 'L', &[apply(m, q)]);
                }
            }
        }
        if path.closed && i + 1 == n {
            d.push('Z');
        }
        prev = s.end();
    }
    d
}

/// Writes an ordering back into the document.
pub fn write(source: &SvgSource, drawing: &Drawing, order: &[Placement]) -> String {
    let text = &source.text;
    let mut out = String::with_capacity(text.len() + order.len() * 64);
    out.push_str(&text[..source.root_open_end]);
    // Pieces by operation, in order.
    let mut by_op: Vec<Vec<&Placement>> = vec![Vec::new(); drawing.operations.len()];
    for p in order {
        if let Some(v) = drawing.pieces.get(p.piece).and_then(|x| by_op.get_mut(x.operation)) {
            v.push(p);
        }
    }
    let piece_path = |pl: &Placement, m: &Affine, out: &mut String| {
        let Some(&(k, j)) = source.piece_element.get(pl.piece) else { return };
        let e = &source.elements[k];
        let id = match (&e.id, e.pieces) {
            (Some(id), 1) => format!(" id=\"{}\"", escape(id)),
            (Some(id), _) => {
                format!(" id=\"{}\"", escape(&if j == 0 { id.clone() } else { format!("{id}-{}", j + 1) }))
            }
            (None, _) => String::new(),
        };
        let attrs = if e.attrs.is_empty() { String::new() } else { format!(" {}", e.attrs) };
        if let Some(l) = &pl.lead_in {
            out.push_str(&format!("\n<path class=\"towpath-lead-in\"{attrs} d=\"{}\"/>", path_data(l, m, source.tol)));
        }
        out.push_str(&format!("\n<path{id}{attrs} d=\"{}\"/>", path_data(&pl.path, m, source.tol)));
    };
    let op_of_layer = |l: Option<usize>| source.op_layer.iter().position(|x| *x == l);
    let mut root_done = false;
    let mut cursor = source.root_open_end;
    let root_pieces: std::collections::HashSet<usize> =
        source.elements.iter().filter(|e| e.layer.is_none() && e.pieces > 0).map(|e| e.range.start).collect();
    for (l, (range, holds)) in source.top.iter().enumerate() {
        // Whatever lies between top-level elements (whitespace, comments) is copied.
        if range.start >= cursor {
            out.push_str(&text[cursor..range.start]);
        }
        cursor = range.end.max(cursor);
        let is_root_piece = root_pieces.contains(&range.start);
        if is_root_piece {
            if !root_done {
                root_done = true;
                if let Some(op) = op_of_layer(None) {
                    let m = IDENTITY;
                    for pl in &by_op[op] {
                        piece_path(pl, &m, &mut out);
                    }
                }
            }
            continue;
        }
        if !holds {
            out.push_str(&text[range.clone()]);
            continue;
        }
        let open = &source.layer_open[&l];
        out.push_str(&text[open.clone()]);
        for r in source.layer_keep.get(&l).into_iter().flatten() {
            out.push('\n');
            out.push_str(&text[r.clone()]);
        }
        let m = source.layer_inverse.get(&l).copied().unwrap_or(IDENTITY);
        if let Some(op) = op_of_layer(Some(l)) {
            for pl in &by_op[op] {
                piece_path(pl, &m, &mut out);
            }
        }
        let tag = text[open.clone()].trim_start_matches('<');
        let name_len = tag.find(|c: char| c.is_whitespace() || c == '/' || c == '>').unwrap_or(tag.len());
        out.push_str(&format!("\n</{}>", &tag[..name_len]));
    }
    if source.root_close_start > cursor {
        out.push_str(&text[cursor..source.root_close_start]);
    }
    out.push_str(&text[source.root_close_start.max(source.root_open_end)..]);
    out
}
