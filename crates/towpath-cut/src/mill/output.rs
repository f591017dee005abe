//! A plan as G-code (one section per tool: tool change, spindle, one plunge per cell, feed
//! moves, retract to the clearance plane, rapids between cells, back to the origin) and as an
//! SVG drawing or HTML report of the linked paths.

use crate::geom::{arc_geometry, Path, Seg, P2};
use crate::mill::link::Plan;
use crate::mill::part::Part;

fn fmt(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

fn feed_moves(path: &Path, out: &mut Vec<String>) {
    let mut prev = path.start;
    for s in &path.segs {
        match *s {
            Seg::Line(p) => out.push(format!("G1 X{} Y{}", fmt(p[0]), fmt(p[1]))),
            Seg::Arc { to, bulge } => match arc_geometry(prev, to, bulge) {
                Some((c, ..)) => out.push(format!(
                    "{} X{} Y{} I{} J{}",
                    if bulge > 0.0 { "G3" } else { "G2" },
                    fmt(to[0]),
                    fmt(to[1]),
                    fmt(c[0] - prev[0]),
                    fmt(c[1] - prev[1])
                )),
                None => out.push(format!("G1 X{} Y{}", fmt(to[0]), fmt(to[1]))),
            },
            Seg::Cubic { .. } => {
                let mut f = Vec::new();
                crate::geom::seg_flatten(prev, s, 1e-3, &mut f);
                for q in f {
                    out.push(format!("G1 X{} Y{}", fmt(q[0]), fmt(q[1])));
                }
            }
        }
        prev = s.end();
    }
}

/// The plan as a G-code program (G21/G90/G17, incremental arc centres).
pub fn gcode(part: &Part, plan: &Plan) -> String {
    let mut out = vec![
        format!("(towpath machine: {})", part.name),
        format!(
            "({} tools, clearance {}, origin {} {})",
            plan.tools.len(),
            fmt(part.clearance),
            fmt(part.origin[0]),
            fmt(part.origin[1])
        ),
        if part.units == "inch" || part.units == "in" { "G20".into() } else { "G21".into() },
        "G90 G17".into(),
    ];
    for tp in &plan.tools {
        let tool = &part.tools[tp.tool];
        out.push(format!("(T{}: radius {}, {} cells)", tool.number, fmt(tool.radius), tp.cells.len()));
        out.push(format!("T{} M6", tool.number));
        out.push(format!("S{} M3", fmt(tool.spindle)));
        out.push(format!("G0 Z{}", fmt(part.clearance)));
        for (c, cp) in &tp.order {
            let cell = &tp.cells[*c];
            let depth = part.features[cell.feature].depth;
            let e = cp.entry();
            out.push(format!("(cell {})", cell.id));
            out.push(format!("G0 X{} Y{}", fmt(e[0]), fmt(e[1])));
            out.push(format!("G1 Z{} F{}", fmt(-depth), fmt(tool.plunge_feed)));
            out.push(format!("F{}", fmt(tool.feed)));
            for m in &cp.moves {
                feed_moves(m, &mut out);
            }
            out.push(format!("G0 Z{}", fmt(part.clearance)));
        }
        out.push(format!("G0 X{} Y{}", fmt(part.origin[0]), fmt(part.origin[1])));
        out.push("M5".into());
    }
    out.push("M30".into());
    out.join("\n") + "\n"
}

fn d_attr(path: &Path) -> String {
    let mut d = format!("M{} {}", fmt(path.start[0]), fmt(-path.start[1]));
    for q in path.flatten(1e-2).iter().skip(1) {
        d.push_str(&format!(" L{} {}", fmt(q[0]), fmt(-q[1])));
    }
    if path.closed {
        d.push('Z');
    }
    d
}

const COLOURS: [&str; 6] = ["#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"];

/// An SVG drawing of the plan: feature boundaries grey, each tool's cuts in its colour, rapids
/// dashed red, entries marked (y up, as on the machine).
pub fn svg(part: &Part, plan: &Plan) -> String {
    let mut pts: Vec<P2> = vec![part.origin];
    for f in &part.features {
        pts.extend(f.boundary.flatten(1e-2));
    }
    let b = crate::geom::bbox_of(&pts);
    let pad = 0.05 * (b[2] - b[0]).max(b[3] - b[1]).max(1.0);
    let (x0, y0, w, h) = (b[0] - pad, -b[3] - pad, b[2] - b[0] + 2.0 * pad, b[3] - b[1] + 2.0 * pad);
    let sw = 0.002 * w.max(h);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"800\" height=\"{}\">\n",
        fmt(x0),
        fmt(y0),
        fmt(w),
        fmt(h),
        fmt(800.0 * h / w)
    );
    s.push_str("<g id=\"features\" fill=\"none\" stroke=\"#999\">\n");
    for f in &part.features {
        s.push_str(&format!(
            "<path stroke-width=\"{}\" d=\"{}\"><title>{}</title></path>\n",
            fmt(sw * 2.0),
            d_attr(&f.boundary),
            f.id
        ));
        for i in &f.islands {
            s.push_str(&format!("<path stroke-width=\"{}\" d=\"{}\"/>\n", fmt(sw * 2.0), d_attr(i)));
        }
    }
    s.push_str("</g>\n");
    for (k, tp) in plan.tools.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let tool = &part.tools[tp.tool];
        s.push_str(&format!(
            "<g id=\"T{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"{}\">\n",
            tool.number,
            fmt(sw)
        ));
        let mut at = part.origin;
        for (c, cp) in &tp.order {
            let e = cp.entry();
            s.push_str(&format!(
                "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#d62728\" stroke-dasharray=\"{} {}\"/>\n",
                fmt(at[0]),
                fmt(-at[1]),
                fmt(e[0]),
                fmt(-e[1]),
                fmt(sw * 4.0),
                fmt(sw * 3.0)
            ));
            for m in &cp.moves {
                s.push_str(&format!("<path d=\"{}\"/>\n", d_attr(m)));
            }
            s.push_str(&format!(
                "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{colour}\"><title>T{} cell {}</title></circle>\n",
                fmt(e[0]),
                fmt(-e[1]),
                fmt(sw * 3.0),
                tool.number,
                tp.cells[*c].id
            ));
            at = cp.exit();
        }
        s.push_str(&format!(
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#d62728\" stroke-dasharray=\"{} {}\"/>\n</g>\n",
            fmt(at[0]),
            fmt(-at[1]),
            fmt(part.origin[0]),
            fmt(-part.origin[1]),
            fmt(sw * 4.0),
            fmt(sw * 3.0)
        ));
    }
    s.push_str("</svg>\n");
    s
}

/// An HTML report: totals per tool and the drawing.
pub fn html(part: &Part, plan: &Plan, solver: &str) -> String {
    let mut rows = String::new();
    for tp in &plan.tools {
        let t = &part.tools[tp.tool];
        let saved = if tp.rapid_before > 0.0 { 100.0 * (1.0 - tp.rapid_after / tp.rapid_before) } else { 0.0 };
        rows.push_str(&format!(
            "<tr><td>T{}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{saved:.1} %</td><td>{:.3} s</td></tr>\n",
            t.number,
            fmt(t.radius),
            tp.cells.len(),
            tp.rapid_before,
            tp.rapid_after,
            tp.solve_seconds
        ));
    }
    format!(
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>towpath machine: {name}</title>\
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:right}}</style></head><body>\n\
<h1>{name}</h1><p>Cells linked per tool from the origin and back (solver: {solver}); rapid X/Y travel before (cells in feature order, each entered at its first vertex) and after. Rapids dashed red; dots mark entries.</p>\n\
<table><tr><th>tool</th><th>radius</th><th>cells</th><th>rapid before</th><th>rapid after</th><th>saved</th><th>solve</th></tr>\n{rows}</table>\n{svg}</body></html>\n",
        name = part.name,
        svg = svg(part, plan)
    )
}
