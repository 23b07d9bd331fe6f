//! Tests of the element tree: positions, names, entities, depth guard and errors.

use super::*;

/// The options of the EAGLE reader.
const STRICT: Options = Options {
    names: Names::Qualified,
    entities: Entities::Strict,
    depth_check: DepthCheck::BeforeAttributes,
    max_depth: 256,
};

/// The options of the SVG reader.
const LENIENT: Options = Options {
    names: Names::Local,
    entities: Entities::KeepRaw,
    depth_check: DepthCheck::AfterAttributes,
    max_depth: 256,
};

fn root(src: &str, options: &Options) -> Node {
    match parse(src.as_bytes(), options) {
        Ok(Some(n)) => n,
        other => panic!("{src:?}: {other:?}"),
    }
}

fn err(src: &[u8], options: &Options) -> XmlError {
    match parse(src, options) {
        Err(e) => e,
        Ok(n) => panic!("{src:?} parsed: {n:?}"),
    }
}

#[test]
fn tree_keeps_elements_attributes_and_start_offsets() {
    let src = "<?xml version=\"1.0\"?>\n<a x=\"1\" y='2'>\n  text<b/><!-- c -->\n  <c k=\"v\"><d/></c>\n</a>";
    let a = root(src, &STRICT);
    assert_eq!(a.name, "a");
    assert_eq!(a.pos, 22);
    assert_eq!(
        a.attrs,
        [
            ("x".to_owned(), "1".to_owned()),
            ("y".to_owned(), "2".to_owned())
        ]
    );
    assert_eq!((a.attr("y"), a.attr("z")), (Some("2"), None));
    let names: Vec<_> = a.children.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["b", "c"]);
    let c = &a.children[1];
    assert_eq!(c.pos, 61);
    assert_eq!(
        (
            line_of(src.as_bytes(), c.pos),
            column_of(src.as_bytes(), c.pos)
        ),
        (4, 3)
    );
    assert_eq!(c.children[0].name, "d");
    assert_eq!(c.children[0].pos, 70);
    assert_eq!(a.child("c").map(|c| c.attr("k")), Some(Some("v")));
    assert_eq!(a.list("c", "d").count(), 1);
    assert_eq!(a.children_named("b").count(), 1);
}

#[test]
fn lines_and_columns_are_one_based_and_clamped() {
    let src = b"ab\ncd\n";
    assert_eq!((line_of(src, 0), column_of(src, 0)), (1, 1));
    assert_eq!((line_of(src, 2), column_of(src, 2)), (1, 3));
    assert_eq!((line_of(src, 3), column_of(src, 3)), (2, 1));
    assert_eq!((line_of(src, 99), column_of(src, 99)), (3, 1));
}

#[test]
fn offsets_count_the_byte_order_mark() {
    let src = "\u{feff}<a>\n<b/></a>";
    let a = root(src, &STRICT);
    assert_eq!((a.pos, a.children[0].pos), (3, 7));
    match err("\u{feff}<a></b>".as_bytes(), &STRICT) {
        XmlError::Syntax { offset, .. } => assert_eq!(offset, 6),
        e => panic!("{e:?}"),
    }
}

#[test]
fn names_are_qualified_or_local() {
    let src = "<svg:svg xmlns:svg=\"u\"><svg:path xlink:href=\"#p\"/></svg:svg>";
    let q = root(src, &STRICT);
    assert_eq!(
        (q.name.as_str(), q.children[0].name.as_str()),
        ("svg:svg", "svg:path")
    );
    let l = root(src, &LENIENT);
    assert_eq!(
        (l.name.as_str(), l.children[0].name.as_str()),
        ("svg", "path")
    );
    // Attribute keys keep their prefix either way.
    assert_eq!(l.children[0].attr("xlink:href"), Some("#p"));
}

#[test]
fn entities_decode_and_unknown_ones_follow_the_policy() {
    let known = "<a v=\"&lt;&amp;&gt;&apos;&quot;&#65;&#x42;\" w=\"a\tb\"/>";
    for options in [&STRICT, &LENIENT] {
        let a = root(known, options);
        assert_eq!(a.attr("v"), Some("<&>'\"AB"));
        // Attribute-value normalisation: a tab becomes a space.
        assert_eq!(a.attr("w"), Some("a b"));
    }
    let unknown = "<a>\n<b v=\"&amp;&ns_svg;\"/></a>";
    match err(unknown.as_bytes(), &STRICT) {
        XmlError::Syntax { offset, .. } => assert_eq!(offset, 4),
        e => panic!("{e:?}"),
    }
    // The raw value is kept whole: the known reference is not decoded either.
    let b = root(unknown, &LENIENT);
    assert_eq!(b.children[0].attr("v"), Some("&amp;&ns_svg;"));
    // Entities in text are skipped like the text itself.
    assert!(root("<a>&nope; x</a>", &STRICT).children.is_empty());
}

#[test]
fn depth_guard_counts_open_elements() {
    let nested = |n: usize, inner: &str| format!("{}{inner}{}", "<e>".repeat(n), "</e>".repeat(n));
    let small = Options {
        max_depth: 3,
        ..STRICT
    };
    // Three open elements, and a self-closing one below them, are accepted.
    let ok = root(&nested(3, "<leaf/>"), &small);
    assert_eq!(ok.children[0].children[0].children[0].name, "leaf");
    let src = nested(4, "");
    match err(src.as_bytes(), &small) {
        XmlError::TooDeep {
            element,
            offset,
            limit,
        } => assert_eq!((element.as_str(), offset, limit), ("e", 9, 3)),
        e => panic!("{e:?}"),
    }
    // A hostile nesting is an error, not a stack overflow.
    let deep = "<a>".repeat(100_000);
    for options in [&STRICT, &LENIENT] {
        assert!(matches!(
            err(deep.as_bytes(), options),
            XmlError::TooDeep { limit: 256, .. }
        ));
    }
}

#[test]
fn depth_check_order_decides_between_too_deep_and_malformed() {
    let src = b"<a><b><c x=\"1\" x=\"2\"></c></b></a>";
    let before = Options {
        max_depth: 2,
        ..STRICT
    };
    let after = Options {
        max_depth: 2,
        ..LENIENT
    };
    assert!(matches!(
        err(src, &before),
        XmlError::TooDeep { offset: 6, .. }
    ));
    assert!(matches!(
        err(src, &after),
        XmlError::Syntax { offset: 6, .. }
    ));
}

#[test]
fn malformed_inputs_are_errors_with_offsets() {
    match err(b"<a>\xff</a>", &STRICT) {
        XmlError::NotUtf8 { offset } => assert_eq!(offset, 3),
        e => panic!("{e:?}"),
    }
    match err(b"<a><b></a>", &LENIENT) {
        XmlError::Syntax { offset, .. } => assert_eq!(offset, 6),
        e => panic!("{e:?}"),
    }
    match err(b"<a><b>", &STRICT) {
        XmlError::UnexpectedEof { element } => assert_eq!(element, "b"),
        e => panic!("{e:?}"),
    }
    match err(b"<a x=1/>", &STRICT) {
        XmlError::Syntax { offset, .. } => assert_eq!(offset, 0),
        e => panic!("{e:?}"),
    }
}

#[test]
fn first_top_level_element_is_the_root() {
    assert!(matches!(parse(b"", &STRICT), Ok(None)));
    assert!(matches!(
        parse(b"<?xml version=\"1.0\"?> <!-- x -->", &LENIENT),
        Ok(None)
    ));
    assert_eq!(root("<a/><b/>", &STRICT).name, "a");
}
