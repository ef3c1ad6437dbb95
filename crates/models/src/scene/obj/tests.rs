//! Tests for [`super::read_obj`].

use super::*;

fn read(text: &str) -> ObjTriangles {
    read_obj(text.as_bytes()).unwrap_or_else(|f| panic!("line {:?}: {}", f.line, f.error))
}

fn fail(text: &str) -> ObjFailure {
    read_obj(text.as_bytes()).expect_err("should fail")
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn positions_only_keep_the_file_numbering() {
    // First use would renumber 2 -> 0, 3 -> 1, 0 -> 2, 1 -> 3.
    let t = read(&format!("{QUAD}f 3 4 1\nf 1 2 3\n"));
    assert_eq!(t.indices, [2, 3, 0, 0, 1, 2]);
    assert_eq!((t.vertex_count, t.split), (4, false));
}

#[test]
fn unused_positions_stay_in_the_buffer() {
    let t = read(&format!("{QUAD}v 5 5 5\nf 4 2 3\n"));
    assert_eq!(t.indices, [3, 1, 2]);
    assert_eq!(t.vertex_count, 5);
}

#[test]
fn agreeing_texcoords_and_normals_keep_the_file_numbering() {
    let attrs = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n";
    let t = read(&format!("{QUAD}{attrs}f 3/3/1 4/4/1 1/1/1\nf 1/1/1 2/2/1 3/3/1\n"));
    assert_eq!(t.indices, [2, 3, 0, 0, 1, 2]);
    assert_eq!((t.vertex_count, t.split), (4, false));
    // v//vn and v/vt forms too.
    let t = read(&format!("{QUAD}{attrs}f 4//1 2//1 3//1\n"));
    assert_eq!((t.indices, t.split), (vec![3, 1, 2], false));
    let t = read(&format!("{QUAD}{attrs}f 4/2 2/3 3/4\n"));
    assert_eq!((t.indices, t.split), (vec![3, 1, 2], false));
}

#[test]
fn split_vertices_are_numbered_by_first_use() {
    // Position 3 appears with texcoords 3 and 4: a seam, two GPU vertices.
    let attrs = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
    let t = read(&format!("{QUAD}{attrs}f 3/3 4/4 1/1\nf 1/1 2/2 3/4\n"));
    assert!(t.split);
    // (3,3) (4,4) (1,1) (2,2) (3,4) in first-use order.
    assert_eq!(t.indices, [0, 1, 2, 2, 3, 4]);
    assert_eq!(t.vertex_count, 5);
}

#[test]
fn relative_indices_polygons_and_objects() {
    // Relative indices count back from the last element read so far.
    let t = read(&format!("{QUAD}f -2 -1 -4\n"));
    assert_eq!(t.indices, [2, 3, 0]);
    // A pentagon becomes a fan of three triangles.
    let t = read(&format!("{QUAD}v 2 2 0\nf 1 2 3 4 5\n"));
    assert_eq!(t.indices, [0, 1, 2, 0, 2, 3, 0, 3, 4]);
    // Objects and groups do not restart the numbering; lines and points
    // are no triangles; comments are dropped.
    let t = read(&format!(
        "o a\n{QUAD}f 1 2 3 # first\ng b\nusemtl m\nl 1 2\np 4\no c\nf 2 3 4\n"
    ));
    assert_eq!(t.indices, [0, 1, 2, 1, 2, 3]);
}

#[test]
fn errors_name_their_line() {
    let f = fail("v 0 0\n");
    assert_eq!(f.line, Some(1));
    assert!(f.error.to_string().contains("position parse error"), "{}", f.error);
    let f = fail(&format!("{QUAD}vn 0 1\n"));
    assert_eq!(f.line, Some(5));
    assert!(matches!(f.error, ObjError::Normal));
    let f = fail(&format!("{QUAD}vt x\n"));
    assert!(matches!(f.error, ObjError::Texcoord));
    // Numbers that are not finite.
    for (bad, word) in [
        ("v nan 0 0", "nan"),
        ("v 0 inf 0", "inf"),
        ("vt 1e400", "1e400"),
        ("vn 0 0 -inf", "-inf"),
    ] {
        let f = fail(&format!("{QUAD}{bad}\n"));
        assert_eq!(f.line, Some(5), "{bad}");
        assert!(
            matches!(&f.error, ObjError::NotFinite(w) if w == word),
            "{bad}: {}",
            f.error
        );
        assert!(f.error.to_string().contains("not a finite number"), "{}", f.error);
    }
    for bad in ["f 1 2 0", "f 1 2 x", "f 1/2/3/4 2 3", "f /1 2 3"] {
        let f = fail(&format!("{QUAD}{bad}\n"));
        assert_eq!(f.line, Some(5), "{bad}");
        assert!(matches!(f.error, ObjError::Face(_)), "{bad}: {}", f.error);
    }
    assert!(matches!(
        fail(&format!("{QUAD}f 1 2\n")).error,
        ObjError::FaceTooShort(2)
    ));
    // A face may only use what is defined above it.
    let f = fail("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n");
    assert_eq!(f.line, Some(3));
    assert!(
        matches!(
            f.error,
            ObjError::OutOfBounds {
                what: "vertex",
                index: 3,
                count: 2
            }
        ),
        "{}",
        f.error
    );
    let f = fail(&format!("{QUAD}f 1/1 2/1 3/1\n"));
    assert!(
        matches!(f.error, ObjError::OutOfBounds { what: "texcoord", .. }),
        "{}",
        f.error
    );
    let f = fail(&format!("{QUAD}f -5 1 2\n"));
    assert!(f.error.to_string().contains("out of bounds"), "{}", f.error);
}
