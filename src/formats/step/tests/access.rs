//! Errors of the typed access layer name the instance, its line and the parameter.

use super::super::StepError;
use super::{ok, parse, wrap};

#[test]
fn wrong_types_name_the_parameter() {
    let file = parse(&wrap(
        "#45=PLANE('',$);\n#46=PLANE('','oops');\n#47=DIRECTION('',(1.,'x',3.));\n\
         #48=(A(1)B(.T.));",
    ));
    let plane = ok(ok(file.get(46)).record("PLANE"));
    let err = ok(plane.param(1, "position"))
        .reference()
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some("line 9: #46 = PLANE: parameter 2 (position) should be a reference, found a string")
    );
    let unset = ok(ok(file.get(45)).record("PLANE"));
    let err = ok(unset.param(1, "position"))
        .entity()
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some("line 8: #45 = PLANE: parameter 2 (position) should be a reference, found $ (unset)")
    );
    let dir = ok(ok(file.get(47)).record("DIRECTION"));
    let err = ok(dir.param(1, "direction_ratios"))
        .reals()
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some(
            "line 10: #47 = DIRECTION: parameter 2 (direction_ratios) item 2 should be a real, found a string"
        )
    );
    let b = ok(ok(file.get(48)).record("B"));
    let err = ok(b.param(0, "flag")).int().err().map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some(
            "line 11: #48 = B (complex instance): parameter 1 (flag) should be an integer, found an enumeration (.T.)"
        )
    );
    let a = ok(ok(file.get(48)).record("A"));
    assert_eq!(
        ok(ok(a.param(0, "")).real()),
        1.0,
        "integers are accepted as reals"
    );
    assert!(ok(a.param(0, "")).string().is_err(), "negative control");
}

#[test]
fn missing_parameters_records_and_entities() {
    let file = parse(&wrap("#1=PLANE('',#99);\n#2=(A()B((1,2)));"));
    let plane = ok(ok(file.get(1)).record("PLANE"));
    let err = plane.param(2, "extra").err().map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some("line 8: #1 = PLANE: parameter 3 (extra) is missing: only 2 present")
    );
    let err = ok(plane.param(1, "position")).entity().err();
    assert_eq!(
        err.as_ref().map(ToString::to_string).as_deref(),
        Some("line 8: #1 = PLANE: parameter 2 (position) refers to #99, which is not in the file")
    );
    assert_eq!(err.and_then(|e| e.entity_id()), Some(1), "the referrer");
    assert_eq!(
        file.check_references()
            .err()
            .map(|e| e.to_string())
            .as_deref(),
        Some("line 8: #1 = PLANE: parameter 2 refers to #99, which is not in the file"),
        "whole-file check names no attribute"
    );
    let err = ok(file.get(2)).record("C").err().map(|e| e.to_string());
    assert_eq!(err.as_deref(), Some("line 9: #2 = (A B) has no C record"));
    let err = ok(file.get(1)).record("LINE").err().map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some("line 8: #1 = PLANE has no LINE record")
    );
    let list = ok(ok(ok(ok(file.get(2)).record("B")).param(0, "pair")).list());
    let err = list.get(2).err().map(|e| e.to_string());
    assert_eq!(
        err.as_deref(),
        Some(
            "line 9: #2 = B (complex instance): parameter 1 (pair) item 3 is missing: only 2 present"
        )
    );
    assert_eq!(file.get(7).err(), Some(StepError::NoSuchEntity { id: 7 }));
    assert_eq!(
        file.get(7).err().map(|e| e.to_string()).as_deref(),
        Some("no entity #7 in the file")
    );
}

#[test]
fn caller_errors_carry_context() {
    let file = parse(&wrap("#3=CIRCLE('',#4,0.);\n#4=A(((1,(2,(3,(4,(5)))))));"));
    let circle = ok(file.get(3));
    assert_eq!(
        circle.invalid("radius is zero").to_string(),
        "line 8: #3 = CIRCLE: radius is zero"
    );
    let radius = ok(ok(circle.record("CIRCLE")).param(2, "radius"));
    assert_eq!(
        radius.invalid("must be positive").to_string(),
        "line 8: #3 = CIRCLE: parameter 3 (radius): must be positive"
    );
    let mut p = ok(ok(ok(file.get(4)).record("A")).param(0, ""));
    for i in [0, 1, 1, 1, 1] {
        p = ok(ok(p.list()).get(i));
    }
    assert_eq!(p.context(), "#4 = A: parameter 1 item 1.2.2.2.…");
    assert_eq!(ok(ok(p.list()).get(0)).int().ok(), Some(5));
}

#[test]
fn type_counts_count_records() {
    let file = parse(&wrap("#1=(A()B());#2=B();#3=C(B(1));"));
    assert_eq!(
        file.type_counts(),
        [("A", 1), ("B", 2), ("C", 1)],
        "typed parameter names are not records"
    );
    let complex: Vec<String> = file
        .entities()
        .filter(|e| e.is_complex())
        .map(|e| e.type_names())
        .collect();
    assert_eq!(complex, ["(A B)"]);
}

#[test]
fn views_print_briefly() {
    let file = parse(&wrap("#1=PLANE('',(1,.T.));"));
    let entity = ok(file.get(1));
    assert_eq!(format!("{entity:?}"), "EntityRef(#1 = PLANE, line 8)");
    let record = ok(entity.record("PLANE"));
    assert_eq!(format!("{record:?}"), "RecordRef(#1 = PLANE)");
    let param = ok(record.param(1, "position"));
    assert_eq!(
        format!("{param:?}"),
        "ParamRef(#1 = PLANE: parameter 2 (position): List([Int(1), Enum(\"T\")]))"
    );
}

#[test]
fn parameters_stay_compact() {
    // The arena's element size drives parse speed and memory; see model.rs.
    assert_eq!(std::mem::size_of::<super::super::model::Param>(), 16);
}
