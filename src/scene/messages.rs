//! Parser errors in the reader's words. ron reports what its parser expected next ("Expected
//! comma", "Expected opening `(`"), which is true but often not what is wrong: `Normal()` is a
//! shader written with parentheses it does not take, `kd: 0.5` is a colour written as one
//! number. [`explain`] looks at the text around the error (the field being written, the token
//! found, the brackets still open) and says what was expected there and how to write it.

use super::spans::open_brackets;
use ron::error::Error;

/// Each variant of an enum with a valid example: `("Sphere", "Sphere(center: ...)")`.
pub type Variants = &'static [(&'static str, &'static str)];

/// Every variant of the format's enums, as a newcomer would write it: the enum's type name,
/// what the user calls it, and each variant with a valid example.
pub const FORMS: &[(&str, &str, Variants)] = &[
    (
        "ShapeDesc",
        "shape",
        &[
            ("Sphere", "Sphere(center: (0, 0, 5), radius: 1)"),
            (
                "InfinitePlane",
                "InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0))",
            ),
            (
                "Triangle",
                "Triangle(a: (0, 0, 0), b: (1, 0, 0), c: (0, 1, 0))",
            ),
            (
                "Rectangle",
                "Rectangle(corner: (-1, 2, 4), u: (2, 0, 0), v: (0, 0, 2))",
            ),
            (
                "TriangleMesh",
                "TriangleMesh(vertices: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], faces: [(0, 1, 2)])",
            ),
            ("Mesh", "Mesh(path: \"assets/blob.obj\")"),
        ],
    ),
    (
        "MaterialDesc",
        "material",
        &[
            ("Named", "Named(\"red\")"),
            ("Phong", "Phong(kd: (0.8, 0.8, 0.8))"),
            ("Mirror", "Mirror()"),
            ("Conductor", "Conductor(material: \"Au\")"),
            (
                "RoughConductor",
                "RoughConductor(alpha: 0.1, material: \"Au\")",
            ),
            (
                "RoughDielectric",
                "RoughDielectric(alpha: 0.1, int_ior: 1.5)",
            ),
            ("RoughPlastic", "RoughPlastic(alpha: 0.1)"),
            ("Plastic", "Plastic()"),
            ("Transmissive", "Transmissive(ior: 1.5)"),
            (
                "NormalMap",
                "NormalMap(normal_map: Image(path: \"bumps.png\"), material: Phong(kd: (0.8, \
                 0.8, 0.8)))",
            ),
        ],
    ),
    (
        "ShaderDesc",
        "shader",
        &[
            ("Intersection", "Intersection()"),
            ("Depth", "Depth(max_distance: 10)"),
            ("Normal", "Normal"),
            ("Direct", "Direct()"),
            ("Global", "Global()"),
            ("Path", "Path()"),
        ],
    ),
    (
        "CameraFields",
        "camera",
        &[
            (
                "Perspective",
                "Perspective(position: (0, 0, -3), look_at: (0, 0, 1), fov: 60)",
            ),
            (
                "Orthographic",
                "Orthographic(position: (0, 0, -3), look_at: (0, 0, 1), height: 4)",
            ),
        ],
    ),
    (
        "LightDesc",
        "light",
        &[
            ("Point", "Point(position: (0, 2, 0), intensity: (7, 7, 7))"),
            (
                "Spot",
                "Spot(position: (0, 2, 0), direction: (0, -1, 0), intensity: (7, 7, 7))",
            ),
            (
                "Directional",
                "Directional(direction: (0, -1, 0), irradiance: (3, 3, 3))",
            ),
            ("Environment", "Environment(image: \"sky.exr\", scale: 1.0)"),
        ],
    ),
    (
        "Model",
        "model",
        &[("Course", "Course"), ("Physical", "Physical")],
    ),
    (
        "Transfer",
        "transfer",
        &[("Srgb", "Srgb"), ("Linear", "Linear")],
    ),
    (
        "Sampling",
        "sampling",
        &[
            ("Uniform", "Uniform"),
            ("Cosine", "Cosine"),
            ("Brdf", "Brdf"),
        ],
    ),
    (
        "LightSampling",
        "light strategy",
        &[("Mis", "Mis"), ("Light", "Light"), ("Brdf", "Brdf")],
    ),
    (
        "LightsPerVertex",
        "light choice",
        &[("All", "All"), ("One", "One"), ("Importance", "Importance")],
    ),
];

/// The example of variant `name` of any enum.
fn form_of(name: &str) -> Option<&'static str> {
    FORMS
        .iter()
        .flat_map(|(_, _, v)| v.iter())
        .find(|(v, _)| *v == name)
        .map(|(_, f)| *f)
}

/// What the value of field `name` is and how it is written, for fields whose name says it.
fn field_form(name: &str) -> Option<&'static str> {
    Some(match name {
        "kd" | "ks" => "a reflectance `(r, g, b)`, each channel from 0 to 1",
        "color" => "a colour `(r, g, b)`",
        "background" | "ambient" | "intensity" | "radiance" => {
            "a colour `(r, g, b)`, each channel >= 0"
        }
        "center" | "point" | "position" | "look_at" | "a" | "b" | "c" | "translate" | "corner" => {
            "a point `(x, y, z)`"
        }
        "u" | "v" => "an edge vector `(x, y, z)`",
        "rotate" => "three angles in degrees `(x, y, z)`",
        "normal" | "up" => "a direction `(x, y, z)`",
        "scale" => "three scale factors `(x, y, z)`",
        "vertices" => "a list of points `[(0, 0, 0), (1, 0, 0), ...]`",
        "faces" => "a list of vertex index triples `[(0, 1, 2), ...]`",
        "normals" => "a list of directions `[(0, 0, 1), ...]`, one per vertex",
        "film" => "the film `(width: 720, height: 576, spp: 1)`",
        "camera" => "`Perspective(...)` or `Orthographic(...)`",
        "shader" => {
            "one of `Intersection()`, `Depth(max_distance: 10)`, `Normal`, `Direct()`, \
             `Global()` and `Path()`"
        }
        "material" => {
            "`Named(\"name\")` for a material of the table, or one written inline: \
             `Phong(kd: (0.8, 0.8, 0.8))`, `Mirror()`, `Conductor(material: \"Au\")`, \
             `RoughConductor(alpha: 0.1, material: \"Au\")`, `RoughDielectric(alpha: 0.1, \
             int_ior: 1.5)`, `RoughPlastic(alpha: 0.1)`, `Plastic()`, `Transmissive(ior: 1.5)` \
             or `NormalMap(normal_map: Image(path: \"bumps.png\"), material: ...)`"
        }
        "shape" => {
            "one of `Sphere(...)`, `InfinitePlane(...)`, `Triangle(...)`, \
             `TriangleMesh(...)` and `Mesh(path: \"file.obj\")`"
        }
        "light" => {
            "`Point(position: (0, 2, 0), intensity: (7, 7, 7))`, `Spot(position: (0, 2, 0), \
             direction: (0, -1, 0), intensity: (7, 7, 7))`, `Directional(direction: (0, -1, \
             0), irradiance: (3, 3, 3))` or `Environment(image: \"sky.exr\")`"
        }
        "transform" => "a transform `(scale: (1, 1, 1), rotate: (0, 0, 0), translate: (0, 0, 0))`",
        "effects" => "the effect switches `(shadows: false, ...)`",
        "materials" => "a map of named materials `{ \"red\": Phong(kd: (0.7, 0.2, 0.2)), ... }`",
        "entities" => "a list of entities `[(shape: ..., material: ...), (light: ...)]`",
        "extends" | "name" | "path" => "a string in double quotes",
        "width" | "spp" | "samples" | "max_depth" | "rr_depth" | "max_specular" | "seed" => {
            "a whole number"
        }
        "height" | "radius" | "max_distance" | "fov" | "shininess" | "ior" => "a number",
        "model" => "`Course` or `Physical`",
        "transfer" => "`Srgb` or `Linear`",
        "sampling" => "`Brdf`, `Uniform` or `Cosine`",
        "shadows" | "reflection" | "refraction" | "indirect" => "`true` or `false`",
        _ => return None,
    })
}

/// Byte offset of 1-based `(line, col)` (col in characters) in `text`, clamped to the text.
pub fn offset_of(text: &str, line: usize, col: usize) -> usize {
    let mut start = 0;
    for _ in 1..line {
        match text[start..].find('\n') {
            Some(i) => start += i + 1,
            None => return text.len(),
        }
    }
    text[start..]
        .char_indices()
        .nth(col.saturating_sub(1))
        .map_or(text.len(), |(i, _)| start + i)
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Offset of the first character at or after `off` that is not white space or a comment.
fn skip_space(text: &str, mut off: usize) -> usize {
    loop {
        let rest = &text[off..];
        let trimmed = rest.trim_start();
        off += rest.len() - trimmed.len();
        if trimmed.starts_with("//") {
            off += trimmed.find('\n').unwrap_or(trimmed.len());
        } else if trimmed.starts_with("/*") {
            match trimmed.find("*/") {
                Some(i) => off += i + 2,
                None => return text.len(),
            }
        } else {
            return off;
        }
    }
}

/// The token at or after `off` (white space skipped; a word `off` is inside of is taken
/// whole), as written, at most 40 characters.
fn token_at(text: &str, off: usize) -> Option<String> {
    let mut off = skip_space(text, off);
    if text[off..].starts_with(is_ident) {
        off -= ident_before(text, off).map_or(0, str::len);
    }
    let rest = &text[off..];
    let first = rest.chars().next()?;
    let len = if first == '"' {
        rest[1..].find('"').map_or(rest.len(), |i| i + 2)
    } else if is_ident(first) || "+-.".contains(first) {
        rest.find(|c: char| !(is_ident(c) || ".+-".contains(c)))
            .unwrap_or(rest.len())
    } else {
        first.len_utf8()
    };
    Some(super::error::clip(&rest[..len], 40))
}

/// The identifier that ends just before `off` (no space between), if any.
fn ident_before(text: &str, off: usize) -> Option<&str> {
    let before = &text[..off];
    let start = before
        .char_indices()
        .rev()
        .take_while(|&(_, c)| is_ident(c))
        .last()?
        .0;
    Some(&before[start..])
}

/// The field whose value starts at `off`: the `name` of `name: <off>`.
fn field_at(text: &str, off: usize) -> Option<&str> {
    let before = text[..off].trim_end();
    let before = before.strip_suffix(':')?.trim_end();
    ident_before(text, before.len())
}

/// The field whose value is being written at `off`: the value starts there, or `off` is
/// inside the brackets of that value (`kd: (1, 1` ...), or inside a variant written as the
/// value (`shape: Sphere(` ...).
fn field_of(text: &str, off: usize) -> Option<&str> {
    if let Some(f) = field_at(text, off) {
        return Some(f);
    }
    let &(_, at) = open_brackets(text, off).last()?;
    let name_start = ident_before(text, at).map_or(at, |n| at - n.len());
    field_at(text, name_start)
}

/// Why field `f` refuses a texture, and which fields take one.
fn no_texture(f: &str) -> String {
    format!(
        "`{f}` takes no texture: only colours and roughnesses do (`kd`, `ks`, `color`, the \
         `*_reflectance` and `specular_transmittance` fields, a rough conductor's or \
         dielectric's `alpha`, `alpha_u` and `alpha_v` (not `RoughPlastic`'s), an emitter's \
         `radiance`)"
    )
}

/// How field `field` is written, as a sentence to append.
fn hint(field: Option<&str>) -> String {
    match field.and_then(|f| Some((f, field_form(f)?))) {
        Some((_, "a string in double quotes")) => String::new(),
        Some((f, form)) => format!(": `{f}` is {form}"),
        None => String::new(),
    }
}

/// `a`, `a or b`, `a, b or c` with each name in backquotes.
fn one_of(names: &[&str]) -> String {
    listed(names, "or")
}

/// `a`, `a and b`, `a, b and c` (with `and` as `conj`), each name in backquotes.
fn listed(names: &[&str], conj: &str) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match q.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} {conj} {last}", rest.join(", ")),
    }
}

/// The edit distance between two short names (case-insensitive).
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// ` Did you mean `x`?` when a name is within two edits of `found` (or equal but for case).
fn did_you_mean(found: &str, names: &[&str]) -> String {
    if found.chars().count() > 64 {
        return String::new();
    }
    names
        .iter()
        .map(|n| (distance(found, n), *n))
        .filter(|&(d, _)| d <= 2)
        .min()
        .map_or(String::new(), |(_, n)| format!(" Did you mean `{n}`?"))
}

/// What the user calls the type ron names `outer`.
fn kind_of(outer: Option<&str>) -> (&str, Option<Variants>) {
    match outer.and_then(|o| FORMS.iter().find(|(t, _, _)| *t == o)) {
        Some((_, kind, forms)) => (kind, Some(forms)),
        None => ("value", None),
    }
}

/// Closing bracket of an opening one.
fn closer(open: char) -> char {
    match open {
        '(' => ')',
        '[' => ']',
        _ => '}',
    }
}

/// The brackets still open at `off`, as words: where each was opened (innermost first) and
/// what closes them all.
fn unclosed(text: &str, off: usize) -> Option<String> {
    let open = open_brackets(text, off);
    let (&(c, at), rest) = open.split_last()?;
    let (line, col) = super::error::line_col(text, at);
    let closers: String = open.iter().rev().map(|&(c, _)| closer(c)).collect();
    let others = match rest {
        [] => String::new(),
        [(c, at)] => {
            let (l, c2) = super::error::line_col(text, *at);
            format!(" (nor is the `{c}` of line {l}, column {c2})")
        }
        _ => format!(" (nor are {} brackets before it)", rest.len()),
    };
    Some(format!(
        "`{c}` opened at line {line}, column {col} is not closed{others}: add `{closers}`"
    ))
}

/// The message for ron error `code` whose span starts at byte `start` of `text`
/// and ends at byte `end`.
pub fn explain(code: &Error, text: &str, start: usize, end: usize) -> String {
    let start = start.min(text.len());
    let found = token_at(text, start);
    let found_q = found
        .as_deref()
        .map_or("the end of the file".to_string(), |t| format!("`{t}`"));
    let at_end = skip_space(text, end.clamp(start, text.len())) >= text.len();
    let syntax = !matches!(
        code,
        Error::Message(_)
            | Error::NoSuchEnumVariant { .. }
            | Error::NoSuchStructField { .. }
            | Error::MissingStructField { .. }
            | Error::DuplicateStructField { .. }
            | Error::InvalidValueForType { .. }
            | Error::ExpectedDifferentLength { .. }
    );
    if syntax && skip_space(text, 0) >= text.len() {
        return "the file is empty: a scene file holds one `Scene(...)`".into();
    }
    if syntax && at_end && !matches!(code, Error::UnclosedBlockComment | Error::ExpectedStringEnd) {
        return match unclosed(text, text.len()) {
            Some(u) => format!("the file ends too early: {u}"),
            None => "the file ends too early".into(),
        };
    }
    match code {
        Error::Eof => match unclosed(text, text.len()) {
            Some(u) => format!("the file ends too early: {u}"),
            None => "the file ends too early".into(),
        },
        Error::ExpectedComma
        | Error::ExpectedStructLikeEnd
        | Error::ExpectedArrayEnd
        | Error::ExpectedMapEnd => {
            if at_end {
                return match unclosed(text, text.len()) {
                    Some(u) => format!("the file ends too early: {u}"),
                    None => "the file ends too early".into(),
                };
            }
            if text[start..].starts_with('(')
                && let Some(name) = ident_before(text, start)
                && form_of(name) == Some(name)
            {
                return format!("`{name}` takes no parentheses: write `{name}`");
            }
            let close = open_brackets(text, start)
                .last()
                .map_or(')', |&(c, _)| closer(c));
            if matches!(code, Error::ExpectedComma) {
                format!(
                    "expected `,` or `{close}` before {found_q}: fields and list items are \
                     separated by commas"
                )
            } else {
                let field = field_of(text, start);
                format!("expected `{close}` here, found {found_q}{}", hint(field))
            }
        }
        Error::ExpectedNamedStructLike("Scene") if open_brackets(text, start).is_empty() => {
            format!(
                "expected `Scene(` here, found {found_q}: a scene file holds one `Scene(...)` \
                 (and comments start with `//`)"
            )
        }
        Error::ExpectedStructLike | Error::ExpectedNamedStructLike(_) => {
            if let Some(name) = ident_before(text, start)
                && let Some(form) = form_of(name)
            {
                return format!(
                    "`{name}` needs its parentheses, even with every field left at its \
                     default: write `{form}`"
                );
            }
            let field = field_at(text, start);
            // A texture where the field takes none.
            if let (Some(f), Some("Image" | "Checkerboard")) = (field, found.as_deref()) {
                return format!("{}{}", no_texture(f), hint(field));
            }
            format!("expected `(` here, found {found_q}{}", hint(field))
        }
        Error::ExpectedArray
        | Error::ExpectedMap
        | Error::ExpectedString
        | Error::ExpectedFloat
        | Error::ExpectedInteger
        | Error::ExpectedBoolean
        | Error::ExpectedUnit => {
            let what = match code {
                Error::ExpectedArray => "a list `[...]`",
                Error::ExpectedMap => "a map `{...}`",
                Error::ExpectedString => "a string in double quotes",
                Error::ExpectedFloat => "a number",
                Error::ExpectedInteger => "a whole number",
                Error::ExpectedBoolean => "`true` or `false`",
                _ => "a value",
            };
            // A texture where the field takes none.
            if let (Some(f), Some("Image" | "Checkerboard")) =
                (field_at(text, start), found.as_deref())
            {
                return no_texture(f);
            }
            // Inside `Named(` the field is the material, but the value is the name.
            let in_named = open_brackets(text, start)
                .last()
                .and_then(|&(_, at)| ident_before(text, at))
                == Some("Named");
            let field = field_of(text, start).filter(|_| !in_named);
            let quote = match (code, found.as_deref()) {
                (Error::ExpectedString, Some(t))
                    if t.starts_with(char::is_alphabetic) && t.chars().all(is_ident) =>
                {
                    format!("; write `\"{t}\"`")
                }
                _ => String::new(),
            };
            let hint = hint(field);
            let hint = if hint.ends_with(what) {
                String::new()
            } else {
                hint
            };
            format!("expected {what}, found {found_q}{quote}{hint}")
        }
        Error::ExpectedIdentifier => {
            let field = field_at(text, start).or_else(|| field_of(text, start));
            match found.as_deref() {
                Some(t)
                    if t.starts_with('"')
                        && t.len() > 2
                        && t[1..t.len() - 1].chars().all(is_ident) =>
                {
                    let inner = &t[1..t.len() - 1];
                    if field == Some("material") {
                        format!(
                            "a material is not a string: write `Named({t})` for the table's \
                             material {t}, or write the material inline, as `{}`",
                            form_of("Phong").unwrap_or_default()
                        )
                    } else {
                        let of = match field.and_then(|f| Some((f, field_form(f)?))) {
                            Some((f, form)) => format!(" (`{f}` is {form})"),
                            None => String::new(),
                        };
                        format!(
                            "expected a name without quotes, found {found_q}: write `{inner}`{of}"
                        )
                    }
                }
                Some(",") => "unexpected `,`: a field name or a closing bracket was expected \
                              (two commas in a row?)"
                    .into(),
                Some("(") if field.and_then(field_form).is_some() => {
                    format!("expected a name before `(`{}", hint(field))
                }
                _ if field.and_then(field_form).is_some() => {
                    format!("expected a name, found {found_q}{}", hint(field))
                }
                _ => format!("expected a field name (`name: value`), found {found_q}"),
            }
        }
        Error::ExpectedDifferentLength { expected, found } => {
            let field = field_of(text, start);
            let expected = match expected.strip_prefix("an array of length ") {
                Some(n) => format!("{n} values"),
                None => expected.clone(),
            };
            format!("expected {expected}, found {found}{}", hint(field))
        }
        Error::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => {
            let (kind, forms) = kind_of(outer.as_deref());
            let found = super::error::clip(found, 40);
            let list = match forms {
                Some(forms) => forms
                    .iter()
                    .map(|(_, f)| format!("`{f}`"))
                    .collect::<Vec<_>>()
                    .join(", "),
                None => one_of(expected),
            };
            let kinds = match kind.strip_suffix('y') {
                Some(stem) => format!("{stem}ies"),
                None => format!("{kind}s"),
            };
            format!(
                "unknown {kind} `{found}`.{} The {kinds} are: {list}",
                did_you_mean(&found, expected)
            )
        }
        Error::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let outer = outer.as_deref().unwrap_or("this value");
            let where_ = if outer == "Scene" {
                "at the top level".to_string()
            } else {
                format!("in {outer}")
            };
            let hint = if outer == "Scene"
                && ["lights", "light", "objects", "shapes", "spheres"].contains(&found.as_str())
            {
                " Lights and shapes are entities: `entities: [(shape: ..., material: ...), \
                 (light: ...)]`."
            } else {
                ""
            };
            format!(
                "unknown field `{}` {where_}.{}{hint} The fields are {}",
                super::error::clip(found, 40),
                did_you_mean(found, expected),
                listed(expected, "and")
            )
        }
        Error::MissingStructField { field, outer } => {
            let outer = outer.as_deref().unwrap_or("this value");
            let example = form_of(outer)
                .filter(|f| f.contains(field))
                .map_or(String::new(), |f| format!(", as in `{f}`"));
            let what = field_form(field).map_or(String::new(), |f| format!(" ({f})"));
            format!("{outer} needs `{field}`{what}{example}")
        }
        Error::DuplicateStructField { field, outer } => format!(
            "`{field}` is written twice in {}: keep one",
            outer.as_deref().unwrap_or("this value")
        ),
        Error::ExpectedDifferentStructName { expected, found } => {
            let found = super::error::clip(found, 40);
            let colon = text[end.min(text.len())..].trim_start().starts_with(':');
            let missing = if colon {
                " (is a `(` missing before it?)"
            } else {
                ""
            };
            if *expected == "Scene" && open_brackets(text, start).is_empty() {
                format!("a scene file holds one `Scene(...)`, found `{found}`{missing}")
            } else {
                format!("expected `(` to open a {expected}, found `{found}`{missing}")
            }
        }
        Error::ExpectedMapColon => format!(
            "expected `:` here, found {found_q}: fields are written `name: value`, map entries \
             `\"key\": value`"
        ),
        Error::TrailingCharacters => format!(
            "unexpected {found_q} after the scene's closing `)`: one closing bracket too many?"
        ),
        Error::IntegerOutOfBounds => format!(
            "number {found_q} is out of range for a whole number here{}",
            hint(field_of(text, start))
        ),
        Error::InvalidIntegerDigit { .. } => format!(
            "expected a whole number, found {found_q}{}",
            hint(field_of(text, start))
        ),
        Error::InvalidValueForType { expected, found } => {
            let field = field_of(text, start);
            format!(
                "expected {expected}, found {}{}",
                super::error::clip(found, 60),
                hint(field)
            )
        }
        Error::UnexpectedChar(c) => format!("unexpected character {c:?}"),
        Error::UnclosedBlockComment => "a `/*` comment is not closed: end it with `*/`".into(),
        Error::ExpectedStringEnd => "a string is not closed: end it with `\"`".into(),
        Error::ExceededRecursionLimit => "brackets nested too deeply (more than 128 levels)".into(),
        // A colour-or-texture that is neither: say what each would look like.
        Error::Message(m) if m.contains("untagged enum Paint") => {
            // `Name(` is reported at its bracket: the name is the word before it.
            let before = text[..start].trim_end();
            let name: String = before
                .chars()
                .rev()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            let field_name = field_before(text, before.len() - name.len());
            let field = field_name.map_or("this value".to_string(), |f| format!("`{f}`"));
            // A roughness (`alpha`, `alpha_u`, `alpha_v`) or a colour.
            let constant = if field_name.is_some_and(|f| f.starts_with("alpha")) {
                "a roughness from 1e-4 to 1"
            } else if field_name == Some("radiance") {
                "a radiance `(r, g, b)`"
            } else {
                "a reflectance `(r, g, b)`"
            };
            // A number is meant as a roughness: its own error says what is wrong with it.
            if name.is_empty()
                && let Some(number) = token_at(text, start)
                && let Ok(v) = number.parse::<f64>()
                && let Err(m) = super::values::Roughness::try_from(v)
            {
                return format!("{field}: {m}; or give a texture");
            }
            // A tuple is meant as a colour (an emitter's radiance, else a reflectance): its own
            // error says what is wrong with it.
            let radiance = field_name == Some("radiance");
            let tuple_error = |tuple: &str| {
                if radiance {
                    ron::from_str::<super::values::Rgb>(tuple).err()
                } else {
                    ron::from_str::<super::values::Reflectance>(tuple).err()
                }
            };
            if name.is_empty()
                && let Some(tuple) = bracketed(text, start)
                && let Some(e) = tuple_error(tuple)
            {
                let what = if radiance {
                    "a radiance `(r, g, b)`, each channel at least 0"
                } else {
                    "a reflectance `(r, g, b)`, each channel from 0 to 1"
                };
                return match e.code {
                    Error::Message(m) => format!("{field}: {m}"),
                    Error::ExpectedDifferentLength { found, .. } => {
                        format!("expected 3 values, found {found}: {field} is {what}, or a texture")
                    }
                    other => format!("{field}: {other}"),
                };
            }
            let empty = bracketed(text, start).is_some_and(|b| b[1..b.len() - 1].trim().is_empty());
            // A named texture: its own error says which field is wrong.
            if !name.is_empty()
                && !empty
                && let Some(fields) = bracketed(text, start)
                && let Err(e) = ron::Options::default()
                    .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
                    .from_str::<super::file::TextureDesc>(&format!("{name}{fields}"))
            {
                let why = match e.code {
                    Error::Message(m) => m,
                    other => other.to_string(),
                };
                return format!("{field}: in `{name}(...)`: {why}");
            }
            let why = if !name.is_empty() && empty {
                format!(
                    "`{name}()` with no field cannot be told from a colour here: give one, as \
                     `{name}(color0: (0.4, 0.4, 0.4))`"
                )
            } else if !name.is_empty() {
                format!("`{name}` is not a texture, or its fields are not")
            } else {
                format!("{found_q} is neither")
            };
            format!(
                "{field} takes {constant} or a texture, \
                 `Checkerboard(color0: (0.9, 0.9, 0.9), color1: (0.1, 0.1, 0.1))` or \
                 `Image(path: \"wood.png\")`: {why}"
            )
        }
        // A value its type refused: name the field it was given for.
        Error::Message(m) => match field_before(text, start) {
            Some(f) if m.starts_with("must be") => format!("`{f}` {m}"),
            Some(f) => format!("`{f}`: {m}"),
            None => m.clone(),
        },
        other => {
            let m = other.to_string();
            let mut c = m.chars();
            match c.next() {
                Some(f) => f.to_lowercase().chain(c).collect(),
                None => m,
            }
        }
    }
}

/// The text of the bracketed value starting at `start` (at its opening `(`), through its
/// matching `)`; `None` if it does not start with one or is not closed.
fn bracketed(text: &str, start: usize) -> Option<&str> {
    let rest = text.get(start..)?;
    let open = rest.find(|c: char| !c.is_whitespace())?;
    if !rest[open..].starts_with('(') {
        return None;
    }
    let mut depth = 0;
    for (i, c) in rest[open..].char_indices() {
        match c {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth == 0 {
                    return Some(&rest[open..open + i + 1]);
                }
            }
            _ => {}
        }
    }
    None
}

/// Where the value that a refused-value error points into starts: for a tuple whose closing
/// bracket is at `at`, its opening bracket (strings and comments skipped); for a signed number
/// (reported after its sign), the sign; otherwise `at` itself.
pub fn value_start(text: &str, at: usize) -> usize {
    if text.as_bytes().get(at) == Some(&b')') {
        return match super::spans::open_brackets(text, at).last() {
            Some(&('(', open)) => open,
            _ => at,
        };
    }
    match at.checked_sub(1).and_then(|b| text.as_bytes().get(b)) {
        Some(b'-' | b'+') => at - 1,
        _ => at,
    }
}

/// The name of the field whose value starts at `start` (`radius` in `radius: 0`), if the
/// text before it is `name:`.
fn field_before(text: &str, start: usize) -> Option<&str> {
    let before = text.get(..start)?.trim_end();
    let before = before.strip_suffix(':')?.trim_end();
    let name_start = before
        .char_indices()
        .rev()
        .take_while(|(_, c)| c.is_ascii_alphanumeric() || *c == '_')
        .last()?
        .0;
    let name = &before[name_start..];
    name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        .then_some(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::{CameraFields, LightDesc, MaterialDesc, ShaderDesc, ShapeDesc};
    use crate::scene::{
        Model, file::LightSampling, file::LightsPerVertex, file::Sampling, file::Transfer,
    };
    use serde::de::DeserializeOwned;

    fn parses<T: DeserializeOwned>(s: &str) -> bool {
        ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str::<T>(s)
            .is_ok()
    }

    /// The variant names ron lists for an unknown variant of `T`.
    fn variants<T: DeserializeOwned + std::fmt::Debug>() -> Vec<&'static str> {
        match ron::from_str::<T>("NoSuchVariantName").unwrap_err().code {
            Error::NoSuchEnumVariant { expected, .. } => expected.to_vec(),
            e => panic!("{e:?}"),
        }
    }

    /// Every example of [`FORMS`] is valid, and every variant of every enum has one.
    #[test]
    fn forms_cover_every_variant_and_parse() {
        let check = |ty: &str, names: Vec<&str>, ok: &dyn Fn(&str) -> bool| {
            let (_, _, forms) = FORMS.iter().find(|(t, _, _)| *t == ty).unwrap();
            let mut listed: Vec<&str> = forms.iter().map(|(n, _)| *n).collect();
            let mut names = names;
            listed.sort();
            names.sort();
            assert_eq!(listed, names, "{ty}");
            for (_, f) in forms.iter() {
                assert!(ok(f), "{ty}: {f}");
            }
        };
        check("ShapeDesc", variants::<ShapeDesc>(), &parses::<ShapeDesc>);
        check(
            "MaterialDesc",
            variants::<MaterialDesc>(),
            &parses::<MaterialDesc>,
        );
        check(
            "ShaderDesc",
            variants::<ShaderDesc>(),
            &parses::<ShaderDesc>,
        );
        check(
            "CameraFields",
            variants::<CameraFields>(),
            &parses::<CameraFields>,
        );
        check("LightDesc", variants::<LightDesc>(), &parses::<LightDesc>);
        check("Model", variants::<Model>(), &parses::<Model>);
        check("Transfer", variants::<Transfer>(), &parses::<Transfer>);
        check("Sampling", variants::<Sampling>(), &parses::<Sampling>);
        check(
            "LightSampling",
            variants::<LightSampling>(),
            &parses::<LightSampling>,
        );
        check(
            "LightsPerVertex",
            variants::<LightsPerVertex>(),
            &parses::<LightsPerVertex>,
        );
        assert_eq!(FORMS.len(), 10);
    }

    #[test]
    fn helpers() {
        assert_eq!(offset_of("ab\ncd", 2, 2), 4);
        assert_eq!(offset_of("ab", 5, 1), 2);
        assert_eq!(field_of("(kd: (1, 1", 9), Some("kd"));
        assert_eq!(field_of("(shape: Sphere(center", 15), Some("shape"));
        assert_eq!(
            did_you_mean("hieght", &["width", "height"]),
            " Did you mean `height`?"
        );
        assert_eq!(one_of(&["a", "b", "c"]), "`a`, `b` or `c`");
        assert_eq!(distance("kitten", "sitting"), 3);
    }
}
