//! The SVG writer: outlines carried to where the bodies are, contact shapes, pressed
//! contacts, labels placed so they do not overlap, title, legend and scale bar.

use super::*;

/// Font size of the part names (mm).
pub const LABEL_FONT_MM: f64 = 3.0;

/// The box a label takes on the page (world mm, y up: `[x0, y0, x1, y1]`) when written at
/// `at` with `align` (the SVG `text-anchor`), as [`Svg::text`] writes it: a generous
/// estimate of sans-serif text, 0.6 em per character.
pub fn label_box(at: [f64; 2], text: &str, align: &str) -> [f64; 4] {
    let w = 0.6 * LABEL_FONT_MM * text.chars().count() as f64;
    let x0 = match align {
        "middle" => at[0] - 0.5 * w,
        "end" => at[0] - w,
        _ => at[0],
    };
    [
        x0,
        at[1] - 0.6 * LABEL_FONT_MM,
        x0 + w,
        at[1] + 0.5 * LABEL_FONT_MM,
    ]
}

pub(super) fn overlaps(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Where to write a label wanted at `at`: there if its box is free, else the nearest free
/// place straight above or below (in steps of a line); its box joins `placed`.
pub(super) fn place_label(at: P, text: &str, align: &str, placed: &mut Vec<[f64; 4]>) -> P {
    let step = 1.2 * LABEL_FONT_MM;
    let candidates = (0..40).map(|k| {
        let k = k as f64;
        let dy = if k == 0.0 {
            0.0
        } else {
            let ring = ((k + 1.0) / 2.0).floor();
            if k % 2.0 == 1.0 {
                ring * step
            } else {
                -ring * step
            }
        };
        [at[0], at[1] + dy]
    });
    let mut chosen = at;
    for q in candidates {
        let b = label_box(q, text, align);
        if !placed.iter().any(|p| overlaps(p, &b)) {
            chosen = q;
            break;
        }
    }
    placed.push(label_box(chosen, text, align));
    chosen
}

/// Bounding box of the drawn points (mm).
#[derive(Clone, Copy, Debug)]
pub(super) struct Bounds {
    min: P,
    max: P,
}

impl Bounds {
    fn new() -> Self {
        Self {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }

    fn add(&mut self, q: P, pad: f64) {
        for ((lo, hi), v) in self.min.iter_mut().zip(&mut self.max).zip(q) {
            *lo = lo.min(v - pad);
            *hi = hi.max(v + pad);
        }
    }
}

/// Writes SVG elements with the y axis flipped (world mm, y up → SVG, y down).
pub(super) struct Svg {
    body: String,
    bounds: Bounds,
}

impl Svg {
    fn pt(q: P) -> String {
        format!("{:.2},{:.2}", q[0], -q[1])
    }

    fn polygon(&mut self, pts: &[P], attrs: &str) {
        for &q in pts {
            self.bounds.add(q, 0.0);
        }
        let s: Vec<String> = pts.iter().map(|&q| Self::pt(q)).collect();
        let _ = writeln!(self.body, r#"<polygon points="{}" {attrs}/>"#, s.join(" "));
    }

    fn polyline(&mut self, pts: &[P], attrs: &str) {
        for &q in pts {
            self.bounds.add(q, 0.0);
        }
        let s: Vec<String> = pts.iter().map(|&q| Self::pt(q)).collect();
        let _ = writeln!(
            self.body,
            r#"<polyline points="{}" fill="none" {attrs}/>"#,
            s.join(" ")
        );
    }

    fn circle(&mut self, c: P, r: f64, attrs: &str) {
        self.bounds.add(c, r);
        let _ = writeln!(
            self.body,
            r#"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" {attrs}/>"#,
            c[0], -c[1], r
        );
    }

    /// Text standing on `at` (its baseline 1 mm below, so it is centred on the point).
    fn text(&mut self, at: P, text: &str, align: &str) {
        let _ = writeln!(
            self.body,
            r#"<text x="{:.2}" y="{:.2}" text-anchor="{align}">{}</text>"#,
            at[0],
            -at[1] + 1.0,
            escape(text)
        );
    }

    fn open(&mut self, attrs: &str) {
        let _ = writeln!(self.body, "<g {attrs}>");
    }

    fn close(&mut self) {
        self.body.push_str("</g>\n");
    }
}

/// Escapes text for SVG.
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Maps a point (mm) by a pose in metres.
pub(super) fn map(x: &Transform, q: P) -> P {
    mul(x.transform_point(mul(q, 1e-3)), 1e3)
}

/// Draws a contact shape placed in the world (m), thin.
pub(super) fn draw_shape(svg: &mut Svg, s: &Shape) {
    let attrs = format!(r#"stroke="{CONTACT_STROKE}" stroke-width="0.25""#);
    match s {
        Shape::Circle(c) => svg.circle(
            mul(c.center, 1e3),
            c.radius * 1e3,
            &format!(r#"fill="none" {attrs}"#),
        ),
        Shape::Segment(g) => svg.polyline(&[mul(g.a, 1e3), mul(g.b, 1e3)], &attrs),
        Shape::Line(l) => {
            let t = [-l.normal[1], l.normal[0]];
            let p = mul(l.point, 1e3);
            svg.polyline(&[sub(p, mul(t, 20.0)), add(p, mul(t, 20.0))], &attrs);
        }
        Shape::Arc(a) => svg.polyline(
            &arc(
                mul(a.center, 1e3),
                a.radius * 1e3,
                a.start,
                a.start + a.sweep,
            ),
            &attrs,
        ),
    }
}

/// What the drawing needs of one contact at `(t, x)`: its shapes in the world (m), whether
/// it is pressed and where.
pub(super) struct ContactView<'a> {
    name: &'a str,
    /// The name in the legend: the presser's pad is the finger's or the mass's.
    label: &'a str,
    shapes: Vec<Shape>,
    active: bool,
    point: Option<P>,
}

/// Draws `action` to scale at time `t` and state `x` (a full state of `action.system`, as
/// [`Action::layout_state`] or a solution row gives), titled `title`: an SVG document in
/// millimetres.
///
/// Each body is an outline built from the parameters and placed by its world pose at
/// `(t, x)` (the drive's value for a prescribed coordinate); bodies the model lacks are not
/// drawn (the simplified model's jack is drawn as part of the wippen). Groups carry ids:
/// `body-key`, `key-capstan`, `key-backcheck`, `body-wippen`, `body-jack`,
/// `body-repetition_lever`, `body-hammer`, `body-presser` (a finger or a mass),
/// `fixed-parts`, `action-bracket` (drawn first, dashed: it stands between keys),
/// `contact-<name>` for each contact's shapes (thin blue), `active-<name>` for the red dot
/// on each pressed contact (gap < 0), which the legend also lists, and `labels` (part
/// names, placed so that no two overlap).
///
/// Errors: a non-finite `t`, a state of the wrong length or with a non-finite entry.
pub fn action_svg(action: &Action, t: f64, x: &[f64], title: &str) -> Result<String> {
    if !t.is_finite() {
        return Err(CoreError::NonFiniteInput {
            what: "t",
            index: 0,
            value: t,
        }
        .into());
    }
    let (rest, carry) = rest_and_carry(action, t, x)?;
    let contacts = contact_views(
        &action.system,
        &action.contacts,
        &action.contact_handles,
        t,
        x,
        |name| match (name, action.presser) {
            ("presser_key", Some(p)) if p.carried => "finger_key",
            ("presser_key", Some(_)) => "mass_key",
            _ => name,
        },
    )?;

    let parts = build_parts(action, &rest);
    let legend = format!(
        "contact shapes of the {} model; white dots: pivots",
        action.kind.name()
    );
    Ok(render(&parts, &carry, &contacts, &legend, title))
}

/// What the drawings need of every contact of `system` (`contacts`: element index by name)
/// at `(t, x)`, named in the legend by `label`.
pub(super) fn contact_views<'a>(
    system: &mbs_core::System,
    contacts: &'a BTreeMap<String, usize>,
    handles: &BTreeMap<String, ContactHandle>,
    t: f64,
    x: &[f64],
    label: impl Fn(&'a str) -> &'a str,
) -> Result<Vec<ContactView<'a>>> {
    let mut ws = system.workspace();
    let mut views = Vec::new();
    for (name, &e) in contacts {
        let name = name.as_str();
        let ctx = system.element_context(&mut ws, t, x, e)?;
        let Some(element) = system.elements().nth(e) else {
            continue;
        };
        let mut gap = [0.0];
        if element.switch_count() > 0 {
            element.switching_functions(&ctx, &mut gap);
        }
        let (shapes, point) = match handles.get(name) {
            Some(c) => {
                let shapes = c
                    .sides()
                    .iter()
                    .flat_map(|(body, shapes)| {
                        let pose = ctx.body_pose(*body);
                        shapes.iter().map(move |s| s.placed(&pose))
                    })
                    .collect();
                (shapes, Some(mul(c.output(&ctx).point, 1e3)))
            }
            None => (Vec::new(), None),
        };
        views.push(ContactView {
            name,
            label: label(name),
            shapes,
            active: gap[0] < 0.0,
            point,
        });
    }
    Ok(views)
}

/// The SVG document of `parts`, each carried from its rest place by its frame's motion in
/// `carry` (fixed parts and frames not in it stay), with the contacts' shapes and pressed
/// dots over them, the part names, and `title` and `legend` (the line under the pressed
/// contacts).
pub(super) fn render(
    parts: &[Part],
    carry: &BTreeMap<String, Transform>,
    contacts: &[ContactView],
    legend: &str,
    title: &str,
) -> String {
    let mut svg = Svg {
        body: String::new(),
        bounds: Bounds::new(),
    };
    let outline = r##"stroke="#333333" stroke-width="0.3" stroke-linejoin="round""##;
    // Rest layout → now, for a part.
    let carried = |part: &Part| {
        part.frame
            .as_ref()
            .and_then(|f| carry.get(f).copied())
            .unwrap_or(Transform::IDENTITY)
    };
    let hidden = r##"stroke="#8c8c8c" stroke-width="0.3" stroke-dasharray="1.5 1""##;
    for part in parts {
        let x_part = carried(part);
        let outline = if part.behind { hidden } else { outline };
        svg.open(&format!(r#"id="{}""#, part.id));
        for (piece, fill) in &part.pieces {
            match piece {
                Outline::Polygon(pts) => {
                    let pts: Vec<P> = pts.iter().map(|&q| map(&x_part, q)).collect();
                    svg.polygon(&pts, &format!(r#"fill="{fill}" {outline}"#));
                }
                Outline::Circle(c, r) => {
                    svg.circle(map(&x_part, *c), *r, &format!(r#"fill="{fill}" {outline}"#))
                }
                Outline::Wire(pts, width) => {
                    let pts: Vec<P> = pts.iter().map(|&q| map(&x_part, q)).collect();
                    svg.polyline(
                        &pts,
                        &format!(r#"stroke="{fill}" stroke-width="{width:.2}""#),
                    );
                }
            }
        }
        for &pv in &part.pivots {
            svg.circle(
                map(&x_part, pv),
                1.0,
                r##"fill="#ffffff" stroke="#000000" stroke-width="0.3""##,
            );
        }
        svg.close();
    }
    svg.open(r#"id="contact-shapes""#);
    for c in contacts {
        svg.open(&format!(r#"id="contact-{}""#, c.name));
        for s in &c.shapes {
            draw_shape(&mut svg, s);
        }
        svg.close();
    }
    svg.close();
    svg.open(r#"id="active-contacts""#);
    for c in contacts.iter().filter(|c| c.active) {
        if let Some(q) = c.point {
            svg.circle(
                q,
                1.4,
                &format!(
                    r#"id="active-{}" fill="{ACTIVE_FILL}" stroke="none""#,
                    c.name
                ),
            );
        }
    }
    svg.close();
    svg.open(&format!(
        r##"id="labels" font-size="{LABEL_FONT_MM}" fill="#222222""##
    ));
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for part in parts {
        let x_part = carried(part);
        for l in &part.labels {
            let a = map(&x_part, l.anchor);
            let at = place_label(add(a, l.offset), &l.text, l.align, &mut placed);
            if at != a {
                svg.polyline(&[a, at], r##"stroke="#555555" stroke-width="0.15""##);
            }
            svg.text(at, &l.text, l.align);
        }
    }
    svg.close();

    frame_document(svg, contacts, legend, title)
}

/// Wraps the drawing in its document: white page fitted around the action with a margin,
/// title above, legend and scale bar below.
pub(super) fn frame_document(
    svg: Svg,
    contacts: &[ContactView],
    legend: &str,
    title: &str,
) -> String {
    let b = svg.bounds;
    // Wide enough for the title and the legend beside the scale bar (text at 0.6 em a
    // character).
    let active: Vec<&str> = contacts
        .iter()
        .filter(|c| c.active)
        .map(|c| c.label)
        .collect();
    let list = if active.is_empty() {
        "none".to_string()
    } else {
        active.join(", ")
    };
    let pressed = format!("contacts pressed: {list}");
    let text_w = |text: &str, size: f64| 0.6 * size * text.chars().count() as f64;
    let right = (b.max[0])
        .max(b.min[0] + text_w(title, 6.0))
        .max(b.min[0] + 4.5 + text_w(legend, 3.5).max(text_w(&pressed, 3.5)) + 6.0 + SCALE_BAR_MM);
    let (x0, x1) = (b.min[0] - MARGIN_MM, right + MARGIN_MM);
    // SVG y runs down: the top of the page is above the action's highest point.
    let top = -b.max[1] - MARGIN_MM - TITLE_SPACE;
    let bottom = -b.min[1] + MARGIN_MM + LEGEND_SPACE;
    let (w, h) = (x1 - x0, bottom - top);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.2}mm" height="{h:.2}mm" viewBox="{x0:.2} {top:.2} {w:.2} {h:.2}" font-family="sans-serif">"#
    );
    let _ = writeln!(
        out,
        r##"<rect x="{x0:.2}" y="{top:.2}" width="{w:.2}" height="{h:.2}" fill="#ffffff"/>"##
    );
    let _ = writeln!(
        out,
        r##"<text id="title" x="{:.2}" y="{:.2}" font-size="6" fill="#111111">{}</text>"##,
        b.min[0],
        -b.max[1] - TITLE_SPACE + 2.0,
        escape(title)
    );
    out.push_str(&svg.body);

    // Legend: pressed contacts, and what the thin lines are.
    let y0 = -b.min[1] + MARGIN_MM;
    let _ = writeln!(out, r##"<g id="legend" font-size="3.5" fill="#222222">"##);
    // Without contacts (the swing test) only the legend line stands.
    if !contacts.is_empty() {
        let _ = writeln!(
            out,
            r#"<circle cx="{:.2}" cy="{:.2}" r="1.4" fill="{ACTIVE_FILL}"/>"#,
            b.min[0] + 1.4,
            y0 - 1.2
        );
        let _ = writeln!(
            out,
            r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
            b.min[0] + 4.5,
            y0,
            escape(&pressed)
        );
        let _ = writeln!(
            out,
            r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{CONTACT_STROKE}" stroke-width="0.25"/>"#,
            b.min[0],
            y0 + 4.8,
            b.min[0] + 3.0,
            y0 + 4.8
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
        b.min[0] + 4.5,
        y0 + 6.0,
        escape(legend)
    );
    out.push_str("</g>\n");

    // Scale bar at the bottom right.
    let (sx1, sy) = (right, y0 + 4.0);
    let sx0 = sx1 - SCALE_BAR_MM;
    let _ = writeln!(
        out,
        r##"<g id="scale-bar" stroke="#000000" stroke-width="0.4"><line x1="{sx0:.2}" y1="{sy:.2}" x2="{sx1:.2}" y2="{sy:.2}"/><line x1="{sx0:.2}" y1="{:.2}" x2="{sx0:.2}" y2="{:.2}"/><line x1="{sx1:.2}" y1="{:.2}" x2="{sx1:.2}" y2="{:.2}"/><text x="{:.2}" y="{:.2}" font-size="3.5" stroke="none" fill="#000000" text-anchor="middle">{SCALE_BAR_MM} mm</text></g>"##,
        sy - 1.2,
        sy + 1.2,
        sy - 1.2,
        sy + 1.2,
        0.5 * (sx0 + sx1),
        sy - 2.0
    );
    out.push_str("</svg>\n");
    out
}
