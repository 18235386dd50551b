//! "Did you mean" suggestions: by edit distance, and for the names of other SDF tools
//! (Quilez's `sdSphere`/`opUnion`, Mercury hg_sdf's `fBox`/`fOpUnionChamfer`, the libraries'
//! `difference`, `smooth_min`, `onion`, …) what this language calls them.

/// The candidate closest to `name`, if it is close enough to be a plausible typo.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, c)| (*d, *c))
        .map(|(_, c)| c)
}

/// The candidate closest to `name`, as [`closest`], where a tie goes to the candidate listed
/// first rather than the first in alphabetical order. Every one-letter name is one edit from
/// every other, so for the names in scope, listed innermost first, the nearest binding wins
/// the tie: `q` inside a field suggests the field's point `p`, not a global `a`.
pub fn closest_in_order<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    let mut best: Option<(usize, &'a str)> = None;
    for c in candidates.into_iter().filter(|c| *c != name) {
        let d = distance(name, c);
        if d <= limit && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// Names of other SDF tools whose spelling differs from this language's by more than a typo,
/// with what to write instead.
const PORTED: &[(&str, &str)] = &[
    ("difference", "subtract"),
    ("intersection", "intersect"),
    ("smooth_min", "smooth_union"),
    ("smin", "smooth_union"),
    ("smooth_max", "smooth_intersect"),
    ("smax", "smooth_intersect"),
    ("smooth_difference", "smooth_subtract"),
    ("smooth_subtraction", "smooth_subtract"),
    ("smooth_intersection", "smooth_intersect"),
    ("blend", "morph"),
    ("onion", "shell"),
    ("offset", "round"),
    ("dilate", "round"),
    ("rounded_box", "round_box"),
    ("capped_cylinder", "cylinder"),
    ("rounded_cone", "round_cone"),
    ("frustum", "capped_cone"),
    ("circular_array", "repeat_polar"),
    // Quilez's names whose plain translation is another primitive here.
    ("sdCapsule", "segment"),
    ("sdVerticalCapsule", "capsule"),
    ("sdCappedCylinder", "cylinder"),
    ("sdCylinder", "infinite_cylinder"),
    ("sdRoundedCylinder", "rounded_cylinder"),
    ("opRep", "repeat"),
    ("opRepetition", "repeat"),
    ("opLimitedRepetition", "repeat"),
    ("opCheapBend", "bend"),
    ("opOnion", "shell"),
    ("opSubtraction", "subtract"),
    ("opSmoothSubtraction", "smooth_subtract"),
    ("opSmoothIntersection", "smooth_intersect"),
    ("fOpDifference", "subtract"),
    ("fOpIntersection", "intersect"),
];

/// hg_sdf's edge blends, `fOp<Union|Intersection|Difference><Variant>`, with the variant.
const EDGES: &[(&str, &str)] = &[
    ("Chamfer", "chamfer"),
    ("Round", "round"),
    ("Stairs", "stairs"),
    ("Columns", "columns"),
];

/// What a user porting a scene from another SDF tool should write for `name`, when `name` is
/// one of that tool's spellings and `known` (this language's functions) has its counterpart:
/// a sentence for the help of an unknown function.
pub fn ported(name: &str, known: &dyn Fn(&str) -> bool) -> Option<String> {
    if name == "radians" {
        // GLSL's `radians(d)` is d degrees in radians; read the other way it would turn a
        // shader's 30 degrees into 30 radians without a word.
        return Some(
            "an angle carries its unit here: for GLSL's `radians(d)` (d degrees) write `30deg` \
             or `d * 1deg`, and for an angle of x radians `0.5rad` or `x * 1rad`"
                .to_string(),
        );
    }
    if let Some((_, ours)) = PORTED.iter().find(|(theirs, _)| *theirs == name) {
        return known(ours).then(|| format!("`{name}` of other SDF tools is `{ours}` here"));
    }
    for (op, ours) in [
        ("Union", "smooth_union"),
        ("Intersection", "smooth_intersect"),
        ("Difference", "smooth_subtract"),
    ] {
        for (theirs, variant) in EDGES {
            if name == format!("fOp{op}{theirs}") {
                let steps = if matches!(*variant, "stairs" | "columns") {
                    ", steps: n"
                } else {
                    ""
                };
                return Some(format!(
                    "hg_sdf's `{name}` is `{ours}(r, a, b, variant: \"{variant}\"{steps})` here"
                ));
            }
        }
    }
    // Quilez's `sdRoundBox`, `opSmoothUnion`, hg_sdf's `fHexPrism`, `fOpEngrave`: the name
    // without its prefix, in snake case.
    let rest = ["sd", "op", "fOp", "f"].iter().find_map(|p| {
        name.strip_prefix(p)
            .filter(|r| r.starts_with(|c: char| c.is_ascii_uppercase()))
    })?;
    let mut snake = String::new();
    for (i, c) in rest.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                snake.push('_');
            }
            snake.push(c.to_ascii_lowercase());
        } else {
            snake.push(c);
        }
    }
    let snake = snake.replace("smooth_intersection", "smooth_intersect");
    let ours = match snake.as_str() {
        "intersection" => "intersect",
        "subtraction" | "difference" => "subtract",
        other => other,
    };
    known(ours).then(|| format!("`{name}` of other SDF tools is `{ours}` here"))
}

/// Edit distance over characters: insertions, deletions, substitutions, and two neighbours
/// swapped (the optimal string alignment form of Damerau's distance), each counting 1, so
/// that `widht` is one edit from `width` as `spher` is from `sphere`.
pub fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // Three rows of the table: the one before the previous (for swaps), the previous, this.
    let mut before: Vec<usize> = vec![0; b.len() + 1];
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut row: Vec<usize> = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        row[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (prev[j] + 1).min(row[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(before[j - 2] + 1);
            }
            row[j] = d;
        }
        std::mem::swap(&mut before, &mut prev);
        std::mem::swap(&mut prev, &mut row);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_typos() {
        assert_eq!(distance("sphere", "spher"), 1);
        assert_eq!(closest("spher", ["sphere", "box", "torus"]), Some("sphere"));
        assert_eq!(closest("xyz", ["sphere", "box"]), None);
    }

    #[test]
    fn ties_go_to_the_name_listed_first() {
        assert_eq!(closest("q", ["p", "a"]), Some("a"));
        assert_eq!(closest_in_order("q", ["p", "a"]), Some("p"));
        assert_eq!(closest_in_order("q", ["a", "p"]), Some("a"));
        // A closer name still wins over one listed earlier.
        assert_eq!(
            closest_in_order("lenght", ["len", "length"]),
            Some("length")
        );
        assert_eq!(closest_in_order("xyz", ["p", "a"]), None);
    }

    #[test]
    fn a_swap_of_neighbours_is_one_edit() {
        assert_eq!(distance("widht", "width"), 1);
        assert_eq!(distance("shpere", "sphere"), 1);
        assert_eq!(distance("ab", "ba"), 1);
        assert_eq!(distance("abc", "ca"), 3);
        assert_eq!(distance("", "box"), 3);
        assert_eq!(distance("torus", ""), 5);
        assert_eq!(distance("kitten", "sitting"), 3);
        assert_eq!(closest("widht", ["width", "height", "aa"]), Some("width"));
        assert_eq!(closest("lenght", ["length", "len"]), Some("length"));
    }

    #[test]
    fn names_of_other_tools_are_translated() {
        let known = |n: &str| crate::check::builtins::builtin(n).is_some();
        let ours = |n: &str| {
            ported(n, &known).map(|h| h.split('`').nth(3).unwrap_or_default().to_string())
        };
        assert_eq!(ours("difference").as_deref(), Some("subtract"));
        assert_eq!(ours("smooth_min").as_deref(), Some("smooth_union"));
        assert_eq!(ours("opUnion").as_deref(), Some("union"));
        assert_eq!(ours("opSmoothUnion").as_deref(), Some("smooth_union"));
        assert_eq!(ours("opIntersection").as_deref(), Some("intersect"));
        assert_eq!(ours("sdSphere").as_deref(), Some("sphere"));
        assert_eq!(ours("sdRoundBox").as_deref(), Some("round_box"));
        assert_eq!(ours("sdHexPrism").as_deref(), Some("hex_prism"));
        assert_eq!(ours("sdCapsule").as_deref(), Some("segment"));
        assert_eq!(ours("fBox").as_deref(), Some("box"));
        assert_eq!(ours("fOpEngrave").as_deref(), Some("engrave"));
        assert_eq!(ours("onion").as_deref(), Some("shell"));
        let chamfer = ported("fOpUnionChamfer", &known).expect("hg_sdf's chamfer");
        assert!(
            chamfer.contains("smooth_union(r, a, b, variant: \"chamfer\")"),
            "{chamfer}"
        );
        assert_eq!(ported("sdNothing", &known), None);
        assert_eq!(ported("frobnicate", &known), None);
    }
}
