//! The grand action's parts, built from its parameters: key, capstan, backcheck, wippen,
//! jack, repetition lever, hammer, presser, bracket and fixed rails; the swing test's hammer on
//! its flange; and the same parts as description outlines.

use super::*;

/// The key: stick with keytop and balance pivot (the capstan is [`capstan_part`], the
/// backcheck [`backcheck_part`], drawn over the hammer).
pub(super) fn key_part(action: &Action) -> Part {
    let k = &action.params.key;
    let mut part = Part::new("body-key", Some("key"));
    let bottom = k.pivot_mm[1];
    let top = k.finger_mm[1];
    let front = k.finger_mm[0] - KEY_FRONT_LIP;
    let back = k.back_pad_mm[0] + k.back_pad_radius_mm + KEY_TAIL;
    part.polygon(rect([front, back], [bottom, top]), KEY_FILL);
    part.polygon(
        rect([front - 0.5, front + KEYTOP[0]], [top, top + KEYTOP[1]]),
        KEYTOP_FILL,
    );
    part.pivots.push(k.pivot_mm);
    let mid = 0.5 * (bottom + top) - 1.0;
    part.label([front + 60.0, mid], [0.0, 0.0], "key", "middle");
    part
}

/// The capstan, standing on the key top: the model's head (a circle) where the model puts
/// it, down to the key top on a post of the head's width when the head stands higher than
/// its radius; when the head's centre is below the key top only its cap shows (it never
/// reaches into the key).
pub(super) fn capstan_part(action: &Action) -> Part {
    let (k, g) = (&action.params.key, &action.params.regulation);
    let mut part = Part::new("key-capstan", Some("key"));
    let top = k.finger_mm[1];
    let c = [
        k.capstan_center_mm[0],
        k.capstan_center_mm[1] + g.capstan_raise_mm,
    ];
    let r = k.capstan_radius_mm;
    if c[1] >= top {
        let mut outline = vec![[c[0] - r, top], [c[0] + r, top]];
        outline.extend(arc(c, r, 0.0, PI));
        part.polygon(outline, BRASS_FILL);
    } else if c[1] + r > top {
        // The cap of the head above the key top, closed by the chord on it.
        let a0 = ((top - c[1]) / r).asin();
        part.polygon(arc(c, r, a0, PI - a0), BRASS_FILL);
    }
    let mid = 0.5 * (k.pivot_mm[1] + top) - 1.0;
    part.label([c[0], mid], [0.0, 0.0], "capstan", "middle");
    part
}

/// The backcheck's face as the model places it, in the layout (world mm, key at rest):
/// its lower and upper ends, and its outward normal (toward the hammer tail at rest).
pub(super) struct BackcheckFace {
    lo: P,
    hi: P,
    n: P,
}

/// Thickness of the backcheck's leather (mm), drawn behind its face.
pub(super) const BACKCHECK_LEATHER: f64 = 1.5;

impl BackcheckFace {
    /// Built as [`Action::build`] builds the contact: the face through the catch point at
    /// its angle, turned so the tail at rest lies on its outward side, moved along that
    /// normal by the regulation's offset.
    fn of(params: &ActionParams) -> Self {
        let (k, g, h) = (&params.key, &params.regulation, &params.hammer);
        let a = k.backcheck_face_angle_deg.to_radians();
        let mut d = [a.cos(), a.sin()];
        let (s, c) = h.rest_angle_deg.to_radians().sin_cos();
        let tb = h.tail_body_mm;
        let tail = [
            h.pivot_mm[0] + c * tb[0] - s * tb[1],
            h.pivot_mm[1] + s * tb[0] + c * tb[1],
        ];
        let to_tail = sub(tail, k.backcheck_mm);
        if -d[1] * to_tail[0] + d[0] * to_tail[1] < 0.0 {
            d = mul(d, -1.0);
        }
        let n = [-d[1], d[0]];
        let mid = add(k.backcheck_mm, mul(n, g.backcheck_offset_mm));
        let hl = k.backcheck_half_length_mm;
        let (a, b) = (sub(mid, mul(d, hl)), add(mid, mul(d, hl)));
        let (lo, hi) = if a[1] <= b[1] { (a, b) } else { (b, a) };
        Self { lo, hi, n }
    }

    /// The head behind the face: leather, then the wooden block.
    fn head(&self) -> [Vec<P>; 2] {
        let (lo, hi, n) = (self.lo, self.hi, self.n);
        let back = mul(n, -BACKCHECK_THICK);
        let leather = vec![
            lo,
            hi,
            sub(hi, mul(n, BACKCHECK_LEATHER)),
            sub(lo, mul(n, BACKCHECK_LEATHER)),
        ];
        let block = vec![
            sub(lo, mul(n, BACKCHECK_LEATHER)),
            sub(hi, mul(n, BACKCHECK_LEATHER)),
            add(hi, back),
            add(lo, back),
        ];
        [leather, block]
    }

    /// Where the wire leaves the head: under its lower end, behind the face.
    fn wire_foot(&self) -> P {
        add(self.lo, mul(self.n, -0.6 * BACKCHECK_THICK))
    }
}

/// The backcheck on the key: the head with its leather face where the model puts the face,
/// on a wire standing up from the key top.
pub(super) fn backcheck_part(action: &Action) -> Part {
    let k = &action.params.key;
    let mut part = Part::new("key-backcheck", Some("key"));
    let face = BackcheckFace::of(&action.params);
    // The wire runs up into the head (drawn over it) from the key top.
    let foot = face.wire_foot();
    part.wire(
        vec![[foot[0], foot[1] + 1.5], [foot[0], k.finger_mm[1]]],
        1.2,
        METAL_FILL,
    );
    let [leather, block] = face.head();
    part.polygon(block, MOLDING_FILL);
    part.polygon(leather, BUCKSKIN_FILL);
    let corner = add(face.lo, mul(face.n, -BACKCHECK_THICK));
    part.label(corner, [12.0, -3.0], "backcheck", "start");
    part
}

/// The wippen: body from the jack centre to its flange, heel down onto the capstan, and the
/// repetition-lever post when there is a lever. In the simplified model the jack is part
/// of it.
pub(super) fn wippen_part(action: &Action, jack_fixed: bool, with_lever: bool) -> Part {
    let p = &action.params;
    let (w, j, r) = (&p.wippen, &p.jack, &p.repetition_lever);
    let mut part = Part::new("body-wippen", Some("wippen"));
    let (jp, wp) = (j.pivot_mm, w.pivot_mm);
    let u = unit(sub(wp, jp), [1.0, 0.0]);
    let n = if u[0] >= 0.0 {
        [-u[1], u[0]]
    } else {
        [u[1], -u[0]]
    };
    let len = (wp[0] - jp[0]).hypot(wp[1] - jp[1]);
    let along = |q: P| (q[0] - jp[0]) * u[0] + (q[1] - jp[1]) * u[1];
    let top = |s: f64| add(add(jp, mul(u, s)), mul(n, WIPPEN_HALF));
    let bot = |s: f64| sub(add(jp, mul(u, s)), mul(n, WIPPEN_HALF));
    let heel = w.heel_mm;
    let hl = w.heel_half_length_mm;
    let s_heel = along(heel);
    let mut outline = vec![top(-6.0)];
    if with_lever {
        let rp = r.pivot_mm;
        let s_rp = along(rp);
        outline.extend([
            top(s_rp - 9.0),
            [rp[0] - 4.0, rp[1] + 4.0],
            [rp[0] + 4.0, rp[1] + 4.0],
            top(s_rp + 9.0),
        ]);
    }
    outline.extend([
        top(len + 7.0),
        bot(len + 7.0),
        bot(s_heel + hl + 2.0),
        [heel[0] + hl, heel[1] + 6.0],
        [heel[0] + hl, heel[1]],
        [heel[0] - hl, heel[1]],
        [heel[0] - hl, heel[1] + 6.0],
        bot(s_heel - hl - 2.0),
        bot(-6.0),
    ]);
    part.polygon(outline, WIPPEN_FILL);
    // Heel cushion.
    part.polygon(
        rect([heel[0] - hl, heel[0] + hl], [heel[1], heel[1] + FELT]),
        FELT_FILL,
    );
    if jack_fixed {
        part.polygon(jack_outline(action), WIPPEN_FILL);
    }
    part.pivots.push(wp);
    if with_lever {
        part.pivots.push(r.pivot_mm);
    }
    part.label([heel[0], heel[1] + 14.0], [0.0, 0.0], "wippen", "middle");
    part
}

/// The jack as an L: the upright along its axis with the top under the knuckle, the toe
/// (tender) reaching forward under the let-off button.
pub(super) fn jack_outline(action: &Action) -> Vec<P> {
    let j = &action.params.jack;
    let n = unit(j.axis, [0.0, 1.0]);
    let t = [n[1], -n[0]];
    let (top, jp) = (j.top_mm, j.pivot_mm);
    let front_top = sub(top, mul(t, j.top_front_edge_mm));
    let back_top = add(top, mul(t, j.top_back_edge_mm));
    let wb = j.top_back_edge_mm.max(2.5);
    let foot = 4.0;
    let tr = j.toe_radius_mm;
    let toe_c = [j.toe_mm[0], j.toe_mm[1] - tr];
    // Where the front edge comes down to just above the toe.
    let s = ((front_top[1] - (j.toe_mm[1] + 1.5)) / n[1].max(0.2)).max(0.0);
    let front_low = sub(front_top, mul(n, s));
    let mut outline = vec![
        front_top,
        back_top,
        add(jp, mul(t, wb)),
        sub(add(jp, mul(t, wb)), mul(n, foot)),
        [toe_c[0] + 1.0, toe_c[1] - tr - 0.8],
    ];
    outline.extend(arc(toe_c, tr + 0.8, 1.5 * PI, 0.5 * PI));
    outline.push(front_low);
    outline
}

pub(super) fn jack_part(action: &Action) -> Part {
    let j = &action.params.jack;
    let mut part = Part::new("body-jack", Some("jack"));
    part.polygon(jack_outline(action), JACK_FILL);
    part.pivots.push(j.pivot_mm);
    part.label(j.toe_mm, [-5.0, -6.0], "jack", "end");
    part
}

/// The repetition lever: its top under the knuckle beside the jack top, its front tip under
/// the drop screw, pinned on the wippen's post.
pub(super) fn lever_part(action: &Action) -> Part {
    let (r, j) = (&action.params.repetition_lever, &action.params.jack);
    let mut part = Part::new("body-repetition_lever", Some("repetition_lever"));
    let n = unit(j.axis, [0.0, 1.0]);
    let t = [n[1], -n[0]];
    let (rp, top) = (r.pivot_mm, r.top_mm);
    let f1 = sub(top, mul(t, r.top_front_edge_mm));
    let b1 = add(top, mul(t, r.top_back_edge_mm));
    let depth = 6.0;
    let tr = r.tip_radius_mm;
    let tip_c = [r.tip_mm[0], r.tip_mm[1] - tr];
    let mut outline = vec![
        r.tip_mm,
        f1,
        b1,
        [rp[0] + 6.0, rp[1] + 4.0],
        [rp[0] + 11.0, rp[1] + 2.0],
        [rp[0] + 11.0, rp[1] - 4.0],
        [rp[0], rp[1] - 5.0],
        [b1[0], b1[1] - depth],
        [f1[0], f1[1] - depth],
        [tip_c[0] + 1.5, tip_c[1] - 4.0],
    ];
    outline.extend(arc(tip_c, tr + 0.5, 1.25 * PI, 0.5 * PI));
    part.polygon(outline, LEVER_FILL);
    part.pivots.push(rp);
    let under = [0.5 * (b1[0] + rp[0]), 0.5 * (b1[1] + rp[1]) - depth];
    part.label(under, [0.0, -4.0], "repetition lever", "middle");
    part
}

/// The hammer in its shank frame: butt with the knuckle, shank, moulding with the tail,
/// felt with its crown; placed in the world by `rest` (its pose in the layout, for the
/// action).
///
/// The moulding is cut to the contact geometry: its back runs from the tail catch point
/// parallel to the backcheck face as it stands at rest, so the tail is the moulding's
/// lowest rear point, the catch face passes through it, and the backcheck (which stands
/// behind that line at rest) never lies inside the head. Where the backcheck reaches up
/// under the crown (`with_backcheck`: the model has one), the felt behind the moulding
/// stops above the backcheck's top.
pub(super) fn hammer_part(params: &ActionParams, rest: &Transform, with_backcheck: bool) -> Part {
    let h = &params.hammer;
    let mut part = Part::new("body-hammer", Some("hammer"));
    let to_rest = |q: P| map(rest, q);
    let place = |pts: Vec<P>| pts.into_iter().map(to_rest).collect::<Vec<_>>();
    // The shape is cut against the backcheck where the layout puts them both.
    let to_body = {
        let inverse = hammer_layout_pose(params).inverse();
        move |q: P| map(&inverse, q)
    };
    let (k, kr) = (h.knuckle_body_mm, h.knuckle_radius_mm);
    let ys = [h.rest_body_mm[1], h.rest_body_mm[1] + SHANK];
    let cr = h.crown_radius_mm;
    let crown_c = [h.strike_body_mm[0], h.strike_body_mm[1] - cr];
    let tail = h.tail_body_mm;
    let tr = h.tail_radius_mm;

    // The backcheck at rest, in the shank frame: its face direction (pointing up the head)
    // and outward normal (toward the tail).
    let face = BackcheckFace::of(params);
    let lo = to_body(face.lo);
    let mut up = unit(sub(to_body(face.hi), lo), [0.0, 1.0]);
    if up[1] < 0.0 {
        up = mul(up, -1.0);
    }
    if up[1] < 0.2 {
        // A face lying along the shank cannot bound the head's back: stand it upright.
        up = [0.0, 1.0];
    }
    let normal = sub(to_body(add(face.lo, face.n)), lo);
    // The back of the moulding: the line through the back of the tail, parallel to the face.
    let tail_back = sub(tail, mul(normal, tr));
    let back_at = |y: f64| add(tail_back, mul(up, (y - tail_back[1]) / up[1]));
    let y_m = (ys[1] + 6.0).min(crown_c[1] - 2.0);
    let x_front = (crown_c[0] - cr - 2.0).min(back_at(y_m)[0] - HEAD_WIDTH);
    // The felt behind the moulding stays above the backcheck's highest point at rest.
    let backcheck_top = face
        .head()
        .iter()
        .flatten()
        .map(|&q| to_body(q)[1])
        .fold(f64::NEG_INFINITY, f64::max);
    let y_cut = if with_backcheck {
        (backcheck_top + HEAD_CLEARANCE).clamp(y_m, crown_c[1] + 0.9 * cr)
    } else {
        y_m
    };

    // Butt: the wood round the centre pin, carrying the knuckle.
    part.polygon(
        place(vec![
            [-7.0, ys[1] + 1.0],
            [k[0] + kr + 2.0, ys[1]],
            [k[0] + kr + 2.0, ys[0]],
            [k[0], k[1]],
            [-7.0, ys[0] - 2.0],
        ]),
        SHANK_FILL,
    );
    part.circle(to_rest(k), kr, BUCKSKIN_FILL);
    part.polygon(place(rect([0.0, x_front + 1.0], ys)), SHANK_FILL);
    // Moulding: front, back line down to the tail, round the tail, up to the shank.
    let mut molding = vec![[x_front, y_m], back_at(y_m), tail_back];
    let a0 = (-normal[1]).atan2(-normal[0]);
    molding.extend(arc(tail, tr, a0, a0 - PI));
    molding.push([x_front, ys[0]]);
    part.polygon(place(molding), MOLDING_FILL);
    // Felt: front flank, over the crown, down its back to the cut, under to the back line.
    let theta = ((y_cut - crown_c[1]) / cr).clamp(-1.0, 1.0).asin();
    let mut felt = vec![[x_front, y_m]];
    felt.extend(arc(crown_c, cr, PI, theta));
    let end = [crown_c[0] + cr * theta.cos(), crown_c[1] + cr * theta.sin()];
    let under = back_at(y_cut);
    if under[0] < end[0] {
        felt.push(under);
    }
    felt.push(back_at(y_m));
    part.polygon(place(felt), HAMMER_FELT_FILL);
    part.pivots.push(h.pivot_mm);
    part.label(
        to_rest([0.55 * x_front, ys[1]]),
        [0.0, 4.0],
        "hammer shank",
        "middle",
    );
    part.label(
        to_rest([crown_c[0] + cr, crown_c[1]]),
        [8.0, 0.0],
        "hammer",
        "start",
    );
    part
}

/// The presser on the key front, in its own frame (origin at its pad's centre): a
/// fingertip coming down from the player's side, or a weight (a steel cylinder as tall as
/// it is wide, to scale for its mass) on its pad.
pub(super) fn presser_part(presser: Option<&Presser>, rest: &Transform) -> Part {
    let mut part = Part::new("body-presser", Some("presser"));
    let place = |pts: Vec<P>| pts.into_iter().map(|q| map(rest, q)).collect::<Vec<_>>();
    let r = PRESSER_PAD_RADIUS_MM;
    match presser {
        Some(p) if !p.carried => {
            // Steel, 7.85 g/cm³: a cylinder of diameter d and height d holds π d³ / 4.
            let volume_mm3 = p.mass_kg / 7.85e-6;
            let d = (4.0 * volume_mm3 / PI).cbrt();
            let mut pad = vec![[-r, r]];
            pad.extend(arc([0.0, 0.0], r, PI, 2.0 * PI));
            pad.push([r, r]);
            part.polygon(place(rect([-0.5 * d, 0.5 * d], [r, r + d])), METAL_FILL);
            part.polygon(place(pad), FELT_FILL);
            let name = format!("{} kg mass", trim_number(p.mass_kg));
            part.label(map(rest, [0.0, r + 0.5 * d]), [0.0, 0.0], name, "middle");
        }
        _ => {
            // The last joint of a finger: its pad (the model's round pad) on the key, the
            // finger rising toward the player, the nail on its back.
            let axis = [
                -(FINGER_TILT_DEG.to_radians().cos()),
                FINGER_TILT_DEG.to_radians().sin(),
            ];
            let side = [axis[1], -axis[0]];
            let len = 45.0;
            let half = FINGER_HALF_WIDTH;
            let a = axis[1].atan2(axis[0]);
            // Round tip of radius r, widening to the finger's width 12 mm up.
            let mut outline = arc([0.0, 0.0], r, a + 0.5 * PI, a + 1.5 * PI);
            outline.push(add(mul(axis, 12.0), mul(side, half)));
            outline.push(add(mul(axis, len), mul(side, half)));
            outline.push(sub(mul(axis, len), mul(side, half)));
            outline.push(sub(mul(axis, 12.0), mul(side, half)));
            part.polygon(place(outline), FINGER_FILL);
            // The nail on the finger's back (the side away from the player).
            let nail = vec![
                add(mul(axis, 2.0), mul(side, r)),
                add(mul(axis, 14.0), mul(side, half)),
                add(mul(axis, 14.0), mul(side, half - 1.2)),
                add(mul(axis, 3.0), mul(side, r - 1.2)),
            ];
            part.polygon(place(nail), FINGER_NAIL_FILL);
            part.label(
                map(rest, mul(axis, 30.0)),
                mul(side, -(half + 3.0)),
                "finger",
                "end",
            );
        }
    }
    part
}

/// `v` as short text: no trailing zeros ("1", "0.5", "2.25").
pub(super) fn trim_number(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The action bracket, seen through the action (it stands between keys, in another
/// plane): a post on the key frame in front of the action carrying the hammer-flange rail
/// and the let-off rail, and an arm back to the wippen flange with a strut up to the rest
/// rail.
pub(super) fn bracket_part(action: &Action, frame_top: f64) -> Part {
    let p = &action.params;
    let (g, w, h) = (&p.regulation, &p.wippen, &p.hammer);
    let mut part = Part::new("action-bracket", None);
    part.behind = true;
    let (hp, wp) = (h.pivot_mm, w.pivot_mm);
    let post = [hp[0] - 44.0, hp[0] - 30.0];
    let flange_rail = [hp[1] - 8.0, hp[1] + 9.0];
    let arm = [wp[1] - 9.0, wp[1] + 5.0];
    let mut outline = vec![
        [post[0], frame_top],
        [post[0], flange_rail[1]],
        [hp[0] - 7.0, flange_rail[1]],
        [hp[0] - 7.0, flange_rail[0]],
        [post[1], flange_rail[0]],
    ];
    if action.contacts.contains_key("let_off_button") {
        let (x, y) = (g.let_off_button_x_mm, g.let_off_button_y_mm);
        let front = 0.5 * (x[0] + x[1]) - 10.0;
        outline.extend([
            [post[1], y + 26.0],
            [front, y + 26.0],
            [front, y + 16.0],
            [post[1], y + 16.0],
        ]);
    }
    outline.push([post[1], arm[1]]);
    let (rx, ry) = (g.rest_rail_x_mm, g.rest_rail_top_y_mm - 11.0);
    if ry > arm[1] && rx[0] + 4.0 > post[1] && rx[1] - 4.0 < wp[0] - 5.0 {
        outline.extend([
            [rx[0] + 4.0, arm[1]],
            [rx[0] + 4.0, ry],
            [rx[1] - 4.0, ry],
            [rx[1] - 4.0, arm[1]],
        ]);
    }
    outline.extend([
        [wp[0] + 5.0, arm[1]],
        [wp[0] + 5.0, arm[0]],
        [post[1], arm[0]],
        [post[1], frame_top],
    ]);
    part.polygon(outline, BRACKET_FILL);
    part.label(
        [post[0], 0.5 * (arm[1] + flange_rail[0])],
        [-3.0, 0.0],
        "action bracket (behind)",
        "end",
    );
    part
}

/// Height of the key frame's top, under the rails (mm).
pub(super) fn key_frame_top(action: &Action) -> f64 {
    let (k, g) = (&action.params.key, &action.params.regulation);
    g.front_rail_top_y_mm
        .min(g.back_rail_top_y_mm)
        .min(k.pivot_mm[1])
        - RAIL_HEIGHT
}

/// The key frame with its rails, the let-off button and its rail, the drop screw, the
/// wippen and hammer flanges, the rest rail and the string.
pub(super) fn fixed_part(action: &Action) -> Part {
    let p = &action.params;
    let (k, g, w, h) = (&p.key, &p.regulation, &p.wippen, &p.hammer);
    let mut part = Part::new("fixed-parts", None);
    let low = key_frame_top(action);
    let fx = g.front_rail_x_mm;
    let bx = g.back_rail_x_mm;
    let kp = k.pivot_mm;
    // Key frame and its three rails, with punchings and cloth.
    part.polygon(rect([fx[0] - 6.0, bx[1]], [low - 4.0, low]), RAIL_FILL);
    part.polygon(
        rect(
            [fx[0] - 4.0, fx[1] + 4.0],
            [low, g.front_rail_top_y_mm - FELT],
        ),
        RAIL_FILL,
    );
    part.polygon(
        rect(fx, [g.front_rail_top_y_mm - FELT, g.front_rail_top_y_mm]),
        CLOTH_FILL,
    );
    part.polygon(
        rect([kp[0] - 12.0, kp[0] + 12.0], [low, kp[1] - FELT]),
        RAIL_FILL,
    );
    part.polygon(
        rect([kp[0] - 5.0, kp[0] + 5.0], [kp[1] - FELT, kp[1]]),
        CLOTH_FILL,
    );
    part.polygon(
        rect([kp[0] - 0.8, kp[0] + 0.8], [kp[1] - FELT, kp[1] + 12.0]),
        METAL_FILL,
    );
    part.polygon(
        rect(bx, [low, g.back_rail_top_y_mm - FELT - 1.0]),
        RAIL_FILL,
    );
    part.polygon(
        rect(
            bx,
            [g.back_rail_top_y_mm - FELT - 1.0, g.back_rail_top_y_mm],
        ),
        FELT_FILL,
    );
    let under = low - 9.0;
    part.label(
        [0.5 * (fx[0] + fx[1]), under],
        [0.0, 0.0],
        "front rail",
        "middle",
    );
    part.label([kp[0], under], [0.0, 0.0], "balance rail", "middle");
    part.label(
        [0.5 * (bx[0] + bx[1]), under],
        [0.0, 0.0],
        "back rail",
        "middle",
    );
    // Let-off button hanging from its rail on a screw.
    if action.contacts.contains_key("let_off_button") {
        let (x, y) = (g.let_off_button_x_mm, g.let_off_button_y_mm);
        let c = 0.5 * (x[0] + x[1]);
        part.polygon(rect([c - 10.0, c + 4.0], [y + 16.0, y + 26.0]), RAIL_FILL);
        part.polygon(rect([c - 1.0, c + 1.0], [y + 5.5, y + 16.0]), METAL_FILL);
        part.polygon(rect(x, [y + FELT, y + 5.5]), MOLDING_FILL);
        part.polygon(rect(x, [y, y + FELT]), CLOTH_FILL);
        part.label([x[0], y + 2.0], [-3.0, 0.0], "let-off button", "end");
    }
    // Hammer flange and its rail; the drop screw goes down through the flange.
    let hp = h.pivot_mm;
    add_hammer_flange(&mut part, hp, "flange rail");
    if action.contacts.contains_key("drop_screw") {
        let (x, y) = (g.drop_screw_x_mm, g.drop_screw_y_mm);
        let c = 0.5 * (x[0] + x[1]);
        part.polygon(rect([c - 1.2, c + 1.2], [y, hp[1] - 3.0]), METAL_FILL);
        part.label([c - 1.2, y + 1.0], [-3.0, 0.0], "drop screw", "end");
    }
    // Wippen flange.
    let wp = w.pivot_mm;
    part.polygon(
        rect([wp[0] - 5.0, wp[0] + 5.0], [wp[1] - 9.0, wp[1] + 5.0]),
        RAIL_FILL,
    );
    // Hammer rest rail with its cushion.
    let rx = g.rest_rail_x_mm;
    let ry = g.rest_rail_top_y_mm;
    part.polygon(rect(rx, [ry - 3.0 - 8.0, ry - 3.0]), RAIL_FILL);
    part.polygon(rect(rx, [ry - 3.0, ry]), FELT_FILL);
    part.label(
        [0.5 * (rx[0] + rx[1]), ry - 9.0],
        [0.0, 0.0],
        "rest rail",
        "middle",
    );
    // The string, seen from the side: a horizontal wire at its height.
    let (sx, sy) = (g.string_x_mm, g.string_y_mm);
    part.wire(vec![[sx[0], sy + 0.5], [sx[1], sy + 0.5]], 1.0, "#555555");
    part.label(
        [0.5 * (sx[0] + sx[1]), sy + 3.0],
        [0.0, 0.0],
        "string",
        "middle",
    );
    part
}

/// The hammer flange on its rail, the hammer's centre pin at `hp`; the rail named `name`.
pub(super) fn add_hammer_flange(part: &mut Part, hp: P, name: &str) {
    part.polygon(
        rect([hp[0] - 27.0, hp[0] - 7.0], [hp[1] - 8.0, hp[1] + 9.0]),
        RAIL_FILL,
    );
    part.polygon(
        vec![
            [hp[0] - 7.0, hp[1] + 8.0],
            [hp[0] + 5.0, hp[1] + 6.0],
            [hp[0] + 5.0, hp[1] - 5.0],
            [hp[0] - 7.0, hp[1] - 7.0],
        ],
        RAIL_FILL,
    );
    part.label([hp[0] - 17.0, hp[1] - 1.0], [0.0, 0.0], name, "middle");
}

/// The parts of the swing test: the hammer flange clamped on its rail, and the hammer with
/// its shank at `shank_angle_rad` in the world.
pub(super) fn pendulum_parts(params: &ActionParams, shank_angle_rad: f64) -> Vec<Part> {
    // The flange is a fork round the butt: seen through the hammer, dashed, with the clamp
    // that holds it above, out of the swing's way.
    let hp = params.hammer.pivot_mm;
    let mut flange = Part::new("fixed-parts", None);
    flange.behind = true;
    flange.polygon(
        vec![
            [hp[0] - 7.0, hp[1] + 10.0],
            [hp[0] + 7.0, hp[1] + 10.0],
            [hp[0] + 5.0, hp[1] - 5.0],
            [hp[0] - 5.0, hp[1] - 5.0],
        ],
        RAIL_FILL,
    );
    flange.polygon(
        rect([hp[0] - 20.0, hp[0] + 20.0], [hp[1] + 10.0, hp[1] + 22.0]),
        METAL_FILL,
    );
    flange.label(
        [hp[0] + 20.0, hp[1] + 16.0],
        [4.0, 0.0],
        "flange, clamped",
        "start",
    );
    vec![
        flange,
        hammer_part(params, &hammer_pose(params, shank_angle_rad), false),
    ]
}

/// The hammer's pose (metres) with its shank at `shank_angle_rad` about its flange pin.
pub(super) fn hammer_pose(params: &ActionParams, shank_angle_rad: f64) -> Transform {
    let h = &params.hammer;
    Transform::new(shank_angle_rad, h.pivot_mm[0] * 1e-3, h.pivot_mm[1] * 1e-3)
}

/// The hammer's pose in the layout: the shank at its rest angle.
pub(super) fn hammer_layout_pose(params: &ActionParams) -> Transform {
    hammer_pose(params, params.hammer.rest_angle_deg.to_radians())
}

/// The swing test drawn to scale: the hammer on its clamped flange with its shank at
/// `shank_angle_rad` in the world (radians, counter-clockwise from the x axis; hanging is
/// [`crate::pendulum::Swing::hanging_shank_angle_rad`]), titled `title`. The hammer is the
/// one [`action_svg`] draws (group `body-hammer`); the flange is `fixed-parts`.
///
/// Errors: a non-finite angle.
pub fn pendulum_svg(params: &ActionParams, shank_angle_rad: f64, title: &str) -> Result<String> {
    if !shank_angle_rad.is_finite() {
        return Err(CoreError::NonFiniteInput {
            what: "shank angle",
            index: 0,
            value: shank_angle_rad,
        }
        .into());
    }
    Ok(render(
        &pendulum_parts(params, shank_angle_rad),
        &BTreeMap::new(),
        &[],
        "the hammer swinging on its flange; white dot: its centre pin",
        title,
    ))
}

/// The swing test as data for a viewer that moves it (see [`scene`]): the clamped flange
/// and the hammer (frame `"hammer"`) hanging, its shank at `hanging_shank_angle_rad`; no
/// contacts.
pub fn pendulum_scene(params: &ActionParams, hanging_shank_angle_rad: f64) -> serde_json::Value {
    serde_json::json!({
        "frames": ["hammer"],
        "parts": parts_json(&pendulum_parts(params, hanging_shank_angle_rad)),
        "contacts": [],
    })
}

/// The motion `[angle (rad), x (mm), y (mm)]` carrying the swing test's hammer from its
/// place in [`pendulum_scene`] (hanging) to `angle_from_hanging_rad` from there: a turn
/// about the flange pin.
pub fn pendulum_carry(params: &ActionParams, angle_from_hanging_rad: f64) -> [f64; 3] {
    let p = params.hammer.pivot_mm;
    let (s, c) = angle_from_hanging_rad.sin_cos();
    // x' = R (x − p) + p, so the translation is p − R p.
    [
        angle_from_hanging_rad,
        p[0] - (c * p[0] - s * p[1]),
        p[1] - (s * p[0] + c * p[1]),
    ]
}

/// The frames a drawing carries, in drawing order.
pub(super) fn drawn_frames(action: &Action) -> Vec<&'static str> {
    let model = action.system.model();
    let mut names = vec!["key", "wippen", "jack", "hammer"];
    for extra in ["repetition_lever", "presser"] {
        if model.body_id(extra).is_ok() {
            names.push(extra);
        }
    }
    names
}

/// Rest poses (q = 0, the layout) of every drawn frame, and the motion carrying each from
/// its rest place to where it is at `(t, x)` (`X_now ∘ X_rest⁻¹`; a prescribed coordinate
/// takes its drive's value).
#[allow(clippy::type_complexity)]
pub(super) fn rest_and_carry(
    action: &Action,
    t: f64,
    x: &[f64],
) -> Result<(BTreeMap<String, Transform>, BTreeMap<String, Transform>)> {
    rest_and_carry_of(&action.system, &drawn_frames(action), t, x)
}

/// [`rest_and_carry`] for the named frames of any system.
#[allow(clippy::type_complexity)]
pub(super) fn rest_and_carry_of(
    system: &mbs_core::System,
    frames: &[&str],
    t: f64,
    x: &[f64],
) -> Result<(BTreeMap<String, Transform>, BTreeMap<String, Transform>)> {
    let model = system.model();
    let mut rest_data = Data::new(model);
    update_poses(model, &mut rest_data, &vec![0.0; model.nv()])?;
    let mut ws = system.workspace();
    let mut carry = BTreeMap::new();
    let mut rest = BTreeMap::new();
    let ctx = system.kinematics(&mut ws, t, x)?;
    for &name in frames {
        let id = model.frame_id(name)?;
        let x0 = frame_pose(model, &rest_data, id);
        let x1 = frame_pose(model, ctx.data, id);
        rest.insert(name.to_string(), x0);
        carry.insert(name.to_string(), x1.compose(&x0.inverse()));
    }
    Ok((rest, carry))
}

/// The parts of `action`, back to front, in their rest places.
pub(super) fn build_parts(action: &Action, rest: &BTreeMap<String, Transform>) -> Vec<Part> {
    let model = action.system.model();
    let is_body = |name: &str| model.body_id(name).is_ok();
    let jack_moves = is_body("jack");
    let with_lever = is_body("repetition_lever");
    let mut parts = vec![
        bracket_part(action, key_frame_top(action)),
        fixed_part(action),
        key_part(action),
        capstan_part(action),
    ];
    parts.push(wippen_part(action, !jack_moves, with_lever));
    if with_lever {
        parts.push(lever_part(action));
    }
    if jack_moves {
        parts.push(jack_part(action));
    }
    if let Some(x0) = rest.get("hammer") {
        let with_backcheck = action.contacts.contains_key("backcheck");
        parts.push(hammer_part(&action.params, x0, with_backcheck));
    }
    if action.contacts.contains_key("backcheck") {
        parts.push(backcheck_part(action));
    }
    if let Some(x0) = rest.get("presser") {
        parts.push(presser_part(action.presser.as_ref(), x0));
    }
    parts
}

/// Thickness of the grand action's drawn parts across the plane (mm) \[M\]: the key 22 mm
/// wide, the wippen and hammer 14 mm, the jack 8 mm; the fixed rails span the keys.
pub(super) const GRAND_THICKNESS_MM: [(&str, f64); 10] = [
    ("fixed-parts", 36.0),
    ("body-key", 22.0),
    ("body-wippen", 14.0),
    ("body-jack", 8.0),
    ("body-repetition_lever", 10.0),
    ("body-hammer", 14.0),
    ("key-backcheck", 14.0),
    ("body-presser", 14.0),
    ("key-capstan", 8.0),
    ("action-bracket", 10.0),
];

/// The thickness (mm) of the grand's drawn part `id` across the plane, 10 mm for one not in
/// [`GRAND_THICKNESS_MM`].
pub(crate) fn grand_thickness_mm(id: &str) -> f64 {
    GRAND_THICKNESS_MM
        .iter()
        .find(|(k, _)| *k == id)
        .map_or(10.0, |(_, h)| *h)
}

/// The grand action's drawing as description outlines: the ground's (world, m) and each
/// body's (its frame, m), with their colours and thicknesses, so that a description
/// written by `piano describe` draws like the built-in model.
#[allow(clippy::type_complexity)]
pub fn grand_outlines(
    action: &Action,
) -> Result<(Vec<OutlinePart>, BTreeMap<String, Vec<OutlinePart>>)> {
    let x = action.layout_state()?;
    let (rest, _) = rest_and_carry(action, 0.0, &x)?;
    let mut ground = Vec::new();
    let mut bodies: BTreeMap<String, Vec<OutlinePart>> = BTreeMap::new();
    for part in build_parts(action, &rest) {
        let thickness = GRAND_THICKNESS_MM
            .iter()
            .find(|(id, _)| *id == part.id)
            .map_or(10.0, |(_, t)| *t)
            * 1e-3;
        // World mm at rest → the frame's coordinates in m.
        let inverse = part
            .frame
            .as_ref()
            .and_then(|f| rest.get(f))
            .map_or(Transform::IDENTITY, |x0| x0.inverse());
        let local = |q: P| inverse.transform_point(mul(q, 1e-3));
        let z = if part.behind { -0.04 } else { 0.0 };
        let mut out = Vec::new();
        for (piece, fill) in &part.pieces {
            let mut o = OutlinePart {
                name: part.id.clone(),
                points: Vec::new(),
                circle: None,
                thickness,
                z,
                color: Some(fill.clone()),
            };
            match piece {
                Outline::Polygon(pts) => {
                    o.points = pts.iter().map(|&q| local(q)).collect();
                    out.push(o);
                }
                Outline::Circle(c, r) => {
                    o.circle = Some(mbs_mechanism::CircleSpec {
                        center: local(*c),
                        radius: r * 1e-3,
                    });
                    out.push(o);
                }
                Outline::Wire(pts, width) => {
                    // Each stretch of wire as a thin quadrilateral.
                    for w in pts.windows(2) {
                        let d = unit(sub(w[1], w[0]), [1.0, 0.0]);
                        let n = mul([-d[1], d[0]], 0.5 * width);
                        let mut q = o.clone();
                        q.points = [add(w[0], n), add(w[1], n), sub(w[1], n), sub(w[0], n)]
                            .into_iter()
                            .map(local)
                            .collect();
                        q.thickness = (width * 1e-3).max(1.5e-3);
                        out.push(q);
                    }
                }
            }
        }
        out.retain(|o| o.circle.is_some() || o.points.len() >= 3);
        match &part.frame {
            None => ground.extend(out),
            Some(f) => bodies.entry(f.clone()).or_default().extend(out),
        }
    }
    Ok((ground, bodies))
}
