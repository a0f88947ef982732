//! Expansion tests: each xacro feature on a small document, the expected URDF written by hand
//! (as ROS 2 xacro 2.1.1 prints it, less its banner).

use super::*;
use std::fmt::Write as _;
use std::fs;

struct Files {
    dir: tempfile::TempDir,
}

impl Files {
    fn new(files: &[(&str, &str)]) -> Files {
        let dir = tempfile::tempdir().expect("tempdir");
        for (name, text) in files {
            let p = dir.path().join(name);
            fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
            fs::write(p, text).expect("write");
        }
        Files { dir }
    }

    fn expand_with(
        &self,
        top: &str,
        args: &[(&str, &str)],
        env: &[(&str, &str)],
    ) -> Result<Expansion, XacroError> {
        let resolver = PackageResolver::new();
        let opts = Options {
            args: args
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            resolver: &resolver,
            env: env
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            cwd: self.dir.path().to_path_buf(),
        };
        expand_file(&self.dir.path().join(top), &opts)
    }

    fn expand(&self, top: &str) -> Result<Expansion, XacroError> {
        self.expand_with(top, &[], &[])
    }
}

/// The expansion of one document, without the declaration and banner.
fn body(doc: &str) -> String {
    body_with(doc, &[])
}

fn body_with(doc: &str, args: &[(&str, &str)]) -> String {
    let f = Files::new(&[("robot.urdf.xacro", doc)]);
    let e = f
        .expand_with("robot.urdf.xacro", args, &[("HOME_X", "/home/x")])
        .unwrap_or_else(|e| panic!("{e}"));
    strip_banner(&e.text)
}

fn strip_banner(text: &str) -> String {
    text.lines().skip(5).collect::<Vec<_>>().join("\n")
}

fn error(doc: &str) -> XacroError {
    let f = Files::new(&[("robot.urdf.xacro", doc)]);
    f.expand("robot.urdf.xacro").expect_err("an error")
}

const HEAD: &str = "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">";

#[test]
fn properties_are_lazy_and_typed() {
    let doc = format!(
        "{HEAD}<xacro:property name=\"w\" value=\"${{l * 2}}\"/>\n<xacro:property name=\"l\" value=\"0.25\"/>\n<xacro:property name=\"s\" value=\"'ab'\"/>\n<box size=\"${{w}} ${{l}} ${{s + 'x'}}\"/><a v=\"${{l + 1}}\"/><b v=\"${{1e-5}} ${{10**16*1.0}} ${{3/2}} ${{True}}\"/></robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <box size=\"0.5 0.25 abx\"/>\n  <a v=\"1.25\"/>\n  <b v=\"1e-05 1e+16 1.5 True\"/>\n</robot>"
    );
}

#[test]
fn property_scopes_and_blocks() {
    let doc = format!(
        "{HEAD}\n<xacro:macro name=\"m\" params=\"\">\n  <xacro:property name=\"p\" value=\"inner\" scope=\"parent\"/>\n  <xacro:property name=\"g\" value=\"global\" scope=\"global\"/>\n</xacro:macro>\n<xacro:m/>\n<xacro:property name=\"blk\"><c/><d/></xacro:property>\n<x p=\"${{p}}\" g=\"${{g}}\"/>\n<xacro:insert_block name=\"blk\"/>\n<xacro:property name=\"q\" default=\"1\"/><xacro:property name=\"q\" default=\"2\"/><q v=\"${{q}}\"/>\n</robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <x p=\"inner\" g=\"global\"/>\n  <c/>\n  <d/>\n  <q v=\"1\"/>\n</robot>"
    );
}

#[test]
fn macros_with_defaults_forwarding_and_blocks() {
    let doc = format!(
        "{HEAD}\n<xacro:property name=\"prefix\" value=\"left_\"/>\n<xacro:macro name=\"link\" params=\"name mass:=1.5 prefix:=^ side:=^|r *origin **extra\">\n  <link name=\"${{prefix}}${{name}}\">\n    <inertial><mass value=\"${{mass}}\"/><xacro:insert_block name=\"origin\"/></inertial>\n    <xacro:insert_block name=\"extra\"/>\n    <side v=\"${{side}}\"/>\n  </link>\n</xacro:macro>\n<xacro:link name=\"a\"><origin xyz=\"0 0 ${{1/4}}\"/><extra><e/><f/></extra></xacro:link>\n<xacro:link name=\"b\" mass=\"2\"><origin/><extra/></xacro:link>\n</robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <link name=\"left_a\">\n    <inertial>\n      <mass value=\"1.5\"/>\n      <origin xyz=\"0 0 0.25\"/>\n    </inertial>\n    <e/>\n    <f/>\n    <side v=\"r\"/>\n  </link>\n  <link name=\"left_b\">\n    <inertial>\n      <mass value=\"2\"/>\n      <origin/>\n    </inertial>\n    <side v=\"r\"/>\n  </link>\n</robot>"
    );
}

#[test]
fn macro_scope_is_the_caller_s_and_macros_nest() {
    // A macro sees the caller's properties (dynamic scope); a macro defined inside another is
    // local to that call.
    let doc = format!(
        "{HEAD}\n<xacro:macro name=\"outer\" params=\"n\">\n  <xacro:macro name=\"inner\" params=\"k\"><i n=\"${{n}}\" k=\"${{k}}\" c=\"${{c}}\"/></xacro:macro>\n  <xacro:inner k=\"${{n*2}}\"/>\n</xacro:macro>\n<xacro:property name=\"c\" value=\"top\"/>\n<xacro:outer n=\"3\"/>\n</robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <i n=\"3\" k=\"6\" c=\"top\"/>\n</robot>"
    );
    let e = error(&format!("{HEAD}\n<xacro:macro name=\"outer\"><xacro:macro name=\"inner\"/></xacro:macro>\n<xacro:outer/>\n<xacro:inner/>\n</robot>"));
    assert_eq!(
        (e.line, e.message.as_str()),
        (4, "unknown macro name: xacro:inner")
    );
}

#[test]
fn args_conditions_and_substitutions() {
    let doc = format!(
        "{HEAD}\n<xacro:arg name=\"gripper\" default=\"true\"/>\n<xacro:arg name=\"n\" default=\"2\"/>\n<xacro:if value=\"$(arg gripper)\"><g/></xacro:if>\n<xacro:unless value=\"${{$(arg n) > 1}}\"><no/></xacro:unless>\n<xacro:if value=\"${{'$(arg n)' == '2'}}\"><two/></xacro:if>\n<e v=\"$(eval 2 * n + 1)\" h=\"$(env HOME_X)\" o=\"$(optenv NOPE fall back)\" d=\"$$(arg n) $${{x}}\"/>\n</robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <g/>\n  <two/>\n  <e v=\"5\" h=\"/home/x\" o=\"fall back\" d=\"$(arg n) ${x}\"/>\n</robot>"
    );
    assert_eq!(
        body_with(&doc, &[("gripper", "false"), ("n", "0")]),
        "<robot name=\"r\">\n  <no/>\n  <e v=\"1\" h=\"/home/x\" o=\"fall back\" d=\"$(arg n) ${x}\"/>\n</robot>"
    );
}

#[test]
fn elements_and_attributes_by_name() {
    let doc = format!(
        "{HEAD}\n<xacro:property name=\"tag\" value=\"sphere\"/>\n<geometry><xacro:element xacro:name=\"${{tag}}\" radius=\"1\"/></geometry>\n<link name=\"a\"><xacro:attribute name=\"type\" value=\"${{tag}}_${{1+1}}\"/></link>\n</robot>"
    );
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <geometry>\n    <sphere radius=\"1\"/>\n  </geometry>\n  <link name=\"a\" type=\"sphere_2\"/>\n</robot>"
    );
}

#[test]
fn includes_with_namespaces_yaml_and_find() {
    let f = Files::new(&[
        ("pkg/package.xml", "<package><name>my_pkg</name></package>"),
        ("pkg/config/params.yaml", "arm:\n  mass: 4.0\n  inertia: {ixx: 0.1, iyy: 0.2}\n  xyz: [0, 0, 0.5]\nnames: [a, b]\n"),
        (
            "pkg/urdf/parts.xacro",
            "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n<xacro:property name=\"p\" value=\"${xacro.load_yaml('../config/params.yaml')}\"/>\n<xacro:macro name=\"part\" params=\"n\"><link name=\"${n}\" m=\"${p['arm']['mass']}\" i=\"${p.arm.inertia.iyy}\" z=\"${p['arm']['xyz'][2]}\" k=\"${len(p['names'])}\"/></xacro:macro>\n</robot>",
        ),
        (
            "pkg/urdf/robot.urdf.xacro",
            "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n<xacro:include filename=\"$(find my_pkg)/urdf/parts.xacro\" ns=\"parts\"/>\n<xacro:include filename=\"parts.xacro\"/>\n<xacro:parts.part n=\"x\"/>\n<xacro:part n=\"y\"/>\n<d v=\"$(dirname)\" q=\"${parts.p['arm']['mass'] * 2}\"/>\n</robot>",
        ),
    ]);
    let e = f
        .expand("pkg/urdf/robot.urdf.xacro")
        .unwrap_or_else(|e| panic!("{e}"));
    let dir = f.dir.path().join("pkg/urdf");
    assert_eq!(
        strip_banner(&e.text),
        format!(
            "<robot name=\"r\">\n  <link name=\"x\" m=\"4.0\" i=\"0.2\" z=\"0.5\" k=\"2\"/>\n  <link name=\"y\" m=\"4.0\" i=\"0.2\" z=\"0.5\" k=\"2\"/>\n  <d v=\"{}\" q=\"8.0\"/>\n</robot>",
            dir.display()
        )
    );
    // The source map: a link from a macro names the macro file and the call.
    let line = e
        .text
        .lines()
        .position(|l| l.contains("name=\"x\""))
        .expect("x")
        + 1;
    let o = e.origin(line).expect("origin");
    assert!(
        e.files[o.file].path.ends_with("pkg/urdf/parts.xacro"),
        "{:?}",
        e.files[o.file].path
    );
    assert_eq!(o.line, 3);
    assert_eq!(
        e.calls_text(o),
        " (macro part called at pkg/urdf/robot.urdf.xacro:4)"
    );
    assert!(o
        .literal
        .as_ref()
        .expect_err("in a macro")
        .contains("body of macro part"));
}

#[test]
fn literal_links_are_marked_for_write_back() {
    let doc = format!(
        "{HEAD}\n  <link name=\"base\">\n    <inertial><mass value=\"${{1+1}}\"/></inertial>\n  </link>\n  <link name=\"${{'arm'}}\"/>\n  <link name=\"hand\"><xacro:if value=\"1\"><visual/></xacro:if></link>\n</robot>"
    );
    let f = Files::new(&[("robot.urdf.xacro", &doc)]);
    let e = f.expand("robot.urdf.xacro").expect("expands");
    let origins: Vec<(&str, &Origin)> = e
        .text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with("<link"))
        .map(|(k, l)| (l.trim(), e.origin(k + 1).expect("origin")))
        .collect();
    assert_eq!(origins.len(), 3);
    assert!(origins[0].1.literal.is_ok());
    assert_eq!(origins[0].1.line, 2);
    let span = &f_text(&e, origins[0].1);
    assert!(
        span.starts_with("<link name=\"base\">") && span.ends_with("</link>"),
        "{span}"
    );
    // A computed name outside a macro body is written where it stands (its values are the file's).
    assert!(origins[1].1.literal.is_ok());
    assert!(origins[2]
        .1
        .literal
        .as_ref()
        .expect_err("xacro inside")
        .contains("comes from xacro"));
    // The source as a robot of its literal links: spans in the source text.
    let robot = e
        .source_robot(0, &[(origins[0].1.start, origins[0].1.end)])
        .expect("source robot");
    assert_eq!(robot.links.len(), 1);
    let l = &robot.links[0];
    assert_eq!(
        (l.name.as_str(), l.line, l.indent.as_str()),
        ("base", 2, "  ")
    );
    let i = l.inertial.as_ref().expect("inertial");
    assert_eq!(
        &robot.text[i.start..i.end],
        "<inertial><mass value=\"${1+1}\"/></inertial>"
    );
}

fn f_text(e: &Expansion, o: &Origin) -> String {
    e.files[o.file].text[o.start..o.end].to_string()
}

#[test]
fn comments_before_directives_go_with_them() {
    let doc = format!("{HEAD}\n  <!-- kept -->\n  <a/>\n  <!-- about p -->\n  <xacro:property name=\"p\" value=\"1\"/>\n  <b/>\n</robot>");
    assert_eq!(
        body(&doc),
        "<robot name=\"r\">\n  <!-- kept -->\n  <a/>\n  <b/>\n</robot>"
    );
}

#[test]
fn errors_name_file_line_and_calls() {
    let e = error(&format!("{HEAD}\n<a v=\"${{nope}}\"/>\n</robot>"));
    assert_eq!(e.line, 2);
    assert!(
        e.message.contains("name 'nope' is not defined"),
        "{}",
        e.message
    );
    let e = error(&format!("{HEAD}\n<a v=\"$(arg missing)\"/>\n</robot>"));
    assert!(
        e.message
            .contains("Undefined substitution argument missing"),
        "{}",
        e.message
    );
    let e = error(&format!(
        "{HEAD}\n<xacro:include filename=\"nothere.xacro\"/>\n</robot>"
    ));
    assert_eq!(e.line, 2);
    assert!(
        e.message.contains("cannot include nothere.xacro"),
        "{}",
        e.message
    );
    let e = error(&format!(
        "{HEAD}\n<xacro:include filename=\"package://pkg/urdf/arm.xacro\"/>\n</robot>"
    ));
    assert!(
        e.message.contains(
            "not a URI, and fails here too: write filename=\"$(find pkg)/urdf/arm.xacro\""
        ),
        "{}",
        e.message
    );
    let e = error(&format!(
        "{HEAD}\n<xacro:macro name=\"m\">\n<xacro:m/>\n</xacro:macro>\n<xacro:m/>\n</robot>"
    ));
    assert!(e.message.contains("recursion in macro m"), "{}", e.message);
    let e = error(&format!("{HEAD}\n<xacro:property name=\"a\" value=\"${{b}}\"/><xacro:property name=\"b\" value=\"${{a}}\"/>\n<x v=\"${{a}}\"/>\n</robot>"));
    assert!(
        e.message
            .contains("circular variable definition: a -> b -> a"),
        "{}",
        e.message
    );
    let e = error(&format!("{HEAD}\n<xacro:frobnicate/>\n</robot>"));
    assert_eq!(
        (e.line, e.message.as_str()),
        (2, "unknown macro name: xacro:frobnicate")
    );
    let e = error(&format!("{HEAD}\n<xacro:macro name=\"m\" params=\"a\">\n  <x v=\"${{a / 0}}\"/>\n</xacro:macro>\n<xacro:m a=\"1\"/>\n</robot>"));
    assert_eq!(e.line, 3);
    assert!(
        e.to_string().ends_with("(in macro m called at ")
            || e.to_string().contains("(in macro m called at "),
        "{e}"
    );
    assert_eq!(e.calls[0].2, 5);
    let e = error(&format!("{HEAD}\n<xacro:if value=\"maybe\"/>\n</robot>"));
    assert!(
        e.message.contains("not a boolean expression"),
        "{}",
        e.message
    );
    let e = error("<robot>\n<link>\n</robot>");
    assert_eq!(e.line, 3);
}

#[test]
fn xacro_files_are_recognised() {
    assert!(is_xacro(Path::new("a.urdf.xacro"), b""));
    assert!(is_xacro(Path::new("a.urdf"), b"<?xml version=\"1.0\"?>\n<robot xmlns:xacro=\"x\"><xacro:property name=\"a\" value=\"1\"/></robot>"));
    // xacro's own output may keep the declaration: it stays a URDF.
    assert!(!is_xacro(
        Path::new("a.urdf"),
        b"<robot xmlns:xacro=\"x\"><link name=\"a\"/></robot>"
    ));
    assert!(!is_xacro(
        Path::new("a.urdf"),
        b"<robot><link name=\"a\"/></robot>"
    ));
}

#[test]
fn hostile_documents_are_errors_not_exhaustion() {
    let h = HEAD;
    // Elements nested 5000 deep.
    let e = error(&format!(
        "{h}{}{}</robot>",
        "<a>".repeat(5000),
        "</a>".repeat(5000)
    ));
    assert!(
        e.message.contains("nested deeper than 1000"),
        "{}",
        e.message
    );
    // An expression nested 5000 deep.
    let e = error(&format!(
        "{h}<a v=\"${{{}1{}}}\"/></robot>",
        "(".repeat(5000),
        ")".repeat(5000)
    ));
    assert!(
        e.message.contains("expression nested deeper than 200"),
        "{}",
        e.message
    );
    // A property doubling itself 40 times (8 TiB of text).
    let mut doc = format!("{h}<xacro:property name=\"p0\" value=\"abcdefgh\"/>");
    for i in 1..40 {
        let _ = write!(
            doc,
            "<xacro:property name=\"p{i}\" value=\"${{p{}}}${{p{}}}\"/>",
            i - 1,
            i - 1
        );
    }
    let e = error(&format!("{doc}<a v=\"${{p39}}\"/></robot>"));
    assert!(e.message.contains("text too long"), "{}", e.message);
    // Macros calling macros ten times, eight deep (10^8 elements).
    let mut doc = h.to_string();
    for i in 0..8 {
        let body = if i < 7 {
            format!("<xacro:m{}/>", i + 1).repeat(10)
        } else {
            "<a/>".into()
        };
        let _ = write!(doc, "<xacro:macro name=\"m{i}\">{body}</xacro:macro>");
    }
    let e = error(&format!("{doc}<xacro:m0/></robot>"));
    assert!(
        e.message.contains("more than 250000 elements"),
        "{}",
        e.message
    );
    assert_eq!(e.calls.len(), 8);
}
