//! `python/rins_topics.py` mirrors the payloads in Python `ctypes`: its generated section (the
//! structures, enums, flag names, topic names and the topics' iceoryx2 limits) is rendered here from
//! the Rust layouts (`rins_recording::schema`, offsets from `offset_of!`), and must equal the
//! committed file. After a layout change, `RINS_BLESS=1 cargo test --test python_ctypes` rewrites
//! it. With `RINS_PYTHON` set, the interpreter itself checks that `ctypes` lays every structure out
//! as Rust does (size, alignment, every field's offset and size), and that the module finds a
//! deployment's default prefix and root where rins puts them.

mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use ipc_types::names;
use rins_recording::TOPICS;
use rins_recording::schema::{FieldKind, PAYLOADS, Prim, StructLayout};
use rins_runtime::ipc;

const BEGIN: &str = "# --- generated from the Rust layouts: do not edit ---\n";
const END: &str = "# --- end of generated section ---\n";

fn module_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("python/rins_topics.py")
}

fn ctype(prim: Prim) -> &'static str {
    match prim {
        Prim::U8 => "ctypes.c_uint8",
        Prim::I8 => "ctypes.c_int8",
        Prim::U16 => "ctypes.c_uint16",
        Prim::I16 => "ctypes.c_int16",
        Prim::U32 => "ctypes.c_uint32",
        Prim::I32 => "ctypes.c_int32",
        Prim::U64 => "ctypes.c_uint64",
        Prim::I64 => "ctypes.c_int64",
        Prim::F32 => "ctypes.c_float",
        Prim::F64 => "ctypes.c_double",
    }
}

/// Every structure, each after the structures nested in it.
fn layouts_in_order() -> Vec<&'static StructLayout> {
    fn visit(layout: &'static StructLayout, out: &mut Vec<&'static StructLayout>) {
        for field in layout.fields {
            if let FieldKind::Nested(inner) = field.kind {
                visit(inner, out);
            }
        }
        if !out.iter().any(|l| l.type_name == layout.type_name) {
            out.push(layout);
        }
    }
    let mut out = Vec::new();
    for layout in PAYLOADS {
        visit(layout, &mut out);
    }
    out
}

/// `NavigatorStandby` → `NAVIGATOR_STANDBY` (and `None`, a Python keyword, → `NONE`).
fn upper_snake(camel: &str) -> String {
    let mut out = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

/// A wire enum: its Rust name, and every variant as (Rust name, value, name tools print).
type WireEnum = (&'static str, Vec<(String, u8, &'static str)>);

macro_rules! wire_enums {
    ($($ty:ident),+ $(,)?) => {
        vec![$((
            stringify!($ty),
            ipc_types::$ty::ALL
                .iter()
                .map(|v| (format!("{v:?}"), *v as u8, v.name()))
                .collect::<Vec<_>>(),
        )),+]
    };
}

fn wire_enums() -> Vec<WireEnum> {
    wire_enums!(
        NavMode,
        Integrity,
        ChannelState,
        FaultReason,
        SensorType,
        SimFault,
        FaultOutcome,
        ReadmitOutcome,
        ServiceKind,
        ServiceState,
        LinkError,
    )
}

/// A flag word's bit names, as `ipc_types` lists them.
type BitNames = &'static [(u32, &'static str)];

/// Flag words: the Python name of the table, the field it describes, and its bit names.
fn flag_tables() -> [(&'static str, &'static str, BitNames); 6] {
    [
        (
            "INTEGRITY_REASONS",
            "NavState.integrity_reasons",
            &ipc_types::integrity_reason::NAMES,
        ),
        (
            "AIDING_SOURCES",
            "NavState.aiding (accepted sources)",
            &ipc_types::aiding::SOURCE_NAMES,
        ),
        (
            "AIDING_STALE",
            "NavState.aiding (stale sources)",
            &ipc_types::aiding::STALE_NAMES,
        ),
        (
            "AIDING_REJECTED",
            "NavState.aiding (rejected sources)",
            &ipc_types::aiding::REJECTED_NAMES,
        ),
        (
            "FUSED_FLAGS",
            "FusedImu.flags",
            &ipc_types::fused_flags::NAMES,
        ),
        ("RAW_IMU_STATUS", "RawImu.status", &ipc_types::status::NAMES),
    ]
}

/// Every topic of the topic table, as the Python constant it becomes: the Rust constant's name.
macro_rules! topic_constants {
    ($($(#[$doc:meta])* $constant:ident $topic:literal $payload:ident $kind:ident;)+) => {
        vec![$((stringify!($constant), names::$constant)),+]
    };
}

/// The Python topic constants in the module's order: the table's, except that the simulator's
/// commands come before its answers (the reverse of the payload order) as they always have.
fn topic_constants() -> Vec<(&'static str, &'static str)> {
    let mut constants = ipc_types::for_each_topic!(topics => topic_constants);
    let answer = constants
        .iter()
        .position(|(c, _)| *c == "SIM_FAULT_APPLIED");
    let command = constants.iter().position(|(c, _)| *c == "SIM_CONTROL");
    if let (Some(answer), Some(command)) = (answer, command) {
        let moved = constants.remove(command);
        constants.insert(answer, moved);
    }
    constants
}

fn render_struct(out: &mut String, layout: &StructLayout) {
    let _ = writeln!(out, "\n\nclass {}(ctypes.Structure):", layout.ros_name);
    let _ = writeln!(
        out,
        "    \"\"\"`{}`: {} bytes, aligned to {}.\"\"\"\n",
        layout.type_name, layout.size, layout.align
    );
    out.push_str("    _fields_ = [\n");
    for field in layout.fields {
        let element = match field.kind {
            FieldKind::Prim(prim) => ctype(prim).to_string(),
            FieldKind::Nested(inner) => inner.ros_name.to_string(),
        };
        let ty = match field.count {
            Some(n) => format!("{element} * {n}"),
            None => element,
        };
        let _ = writeln!(out, "        (\"{}\", {ty}),", field.rust_name);
    }
    out.push_str("    ]\n\n");
    out.push_str("    @staticmethod\n    def type_name() -> str:\n");
    out.push_str("        \"\"\"The iceoryx2 type name of the Rust payload.\"\"\"\n");
    let _ = writeln!(out, "        return \"{}\"", layout.type_name);
}

fn render() -> String {
    let mut out = String::from(BEGIN);
    let _ = writeln!(
        out,
        "\n#: Layout version every payload carries in `version`.\nPAYLOAD_VERSION = {}",
        ipc_types::PAYLOAD_VERSION
    );
    out.push_str("\n# Topic names.\n");
    let constants = topic_constants();
    for (constant, topic) in &constants {
        let _ = writeln!(out, "{constant} = \"{topic}\"");
    }
    out.push_str("#: Both navigator lanes: primary, hot standby.\n");
    let _ = writeln!(out, "NAV_LANES = (NAV_STATE, NAV_STATE_STANDBY)");
    out.push_str("#: The short names `rins echo` accepts.\nSHORT_NAMES = {\n");
    for (short, topic) in names::TOPICS {
        let _ = writeln!(out, "    \"{short}\": \"{topic}\",");
    }
    out.push_str("}\n");

    out.push_str(
        "\n# Limits every rins process opens a topic with; a subscriber asks for the same, since\n\
         # iceoryx2 refuses to open a service with more than it was created for.\n",
    );
    let _ = writeln!(out, "MAX_PUBLISHERS = {}", ipc::MAX_PUBLISHERS);
    let _ = writeln!(out, "MAX_SUBSCRIBERS = {}", ipc::MAX_SUBSCRIBERS);
    let _ = writeln!(out, "MAX_NODES = {}", ipc::MAX_NODES);
    let _ = writeln!(out, "SUBSCRIBER_BUFFER = {}", ipc::SUBSCRIBER_BUFFER);
    out.push_str("#: History kept for late subscribers, by topic (none for a topic not listed).\n");
    out.push_str("HISTORY_SIZE = {\n");
    for (topic, _) in TOPICS {
        let history = ipc::history_size(topic);
        if history > 0 {
            let _ = writeln!(out, "    \"{topic}\": {history},");
        }
    }
    out.push_str("}\n");

    for (name, variants) in wire_enums() {
        let _ = writeln!(out, "\n\nclass {name}(enum.IntEnum):");
        let _ = writeln!(
            out,
            "    \"\"\"`ipc_types::{name}`, carried as a `u8` field.\"\"\"\n"
        );
        for (variant, value, _) in &variants {
            let _ = writeln!(out, "    {} = {value}", upper_snake(variant));
        }
    }
    out.push_str(
        "\n\n#: The name tools print for each enum value (`rins echo`, `rins status`).\nWIRE_NAMES = {\n",
    );
    for (name, variants) in wire_enums() {
        let _ = writeln!(out, "    {name}: {{");
        for (_, value, text) in &variants {
            let _ = writeln!(out, "        {value}: \"{text}\",");
        }
        out.push_str("    },\n");
    }
    out.push_str("}\n");

    for (constant, what, table) in flag_tables() {
        let _ = writeln!(
            out,
            "\n#: Bits of {what}, with their names.\n{constant} = {{"
        );
        for (bit, text) in table {
            let _ = writeln!(out, "    0x{bit:x}: \"{text}\",");
        }
        out.push_str("}\n");
    }

    for layout in layouts_in_order() {
        render_struct(&mut out, layout);
    }

    out.push_str("\n\n#: The payload each topic carries.\nTOPIC_PAYLOADS = {\n");
    for (topic, layout) in TOPICS {
        let constant = constants
            .iter()
            .find(|(_, t)| *t == topic)
            .map(|(c, _)| *c)
            .unwrap_or_else(|| panic!("{topic} has no Python constant"));
        let _ = writeln!(out, "    {constant}: {},", layout.ros_name);
    }
    out.push_str("}\n");
    out.push_str(END);
    out
}

/// The committed file split around its generated section: (before, section, after).
fn split(text: &str) -> (&str, &str, &str) {
    let begin = text
        .find(BEGIN)
        .expect("python/rins_topics.py lacks the start marker");
    let end = text[begin..]
        .find(END)
        .map(|i| begin + i + END.len())
        .expect("python/rins_topics.py lacks the end marker");
    (&text[..begin], &text[begin..end], &text[end..])
}

#[test]
fn the_python_module_is_generated_from_the_rust_layouts() {
    let path = module_path();
    let text = std::fs::read_to_string(&path).expect("cannot read python/rins_topics.py");
    let (before, section, after) = split(&text);
    let rendered = render();
    if std::env::var_os("RINS_BLESS").is_some() {
        std::fs::write(&path, format!("{before}{rendered}{after}"))
            .expect("cannot write python/rins_topics.py");
        return;
    }
    assert!(
        section == rendered,
        "python/rins_topics.py is out of date with the Rust layouts: run \
         `RINS_BLESS=1 cargo test --test python_ctypes` and commit the result"
    );
}

/// Every structure's layout as JSON: name, size, alignment, fields with offset and size.
fn layouts_json() -> serde_json::Value {
    let structs: Vec<serde_json::Value> = layouts_in_order()
        .into_iter()
        .map(|layout| {
            let fields: Vec<serde_json::Value> = layout
                .fields
                .iter()
                .map(|f| {
                    serde_json::json!({ "name": f.rust_name, "offset": f.offset, "size": f.size })
                })
                .collect();
            serde_json::json!({
                "name": layout.ros_name,
                "type_name": layout.type_name,
                "size": layout.size,
                "align": layout.align,
                "fields": fields,
            })
        })
        .collect();
    serde_json::Value::Array(structs)
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn python_ctypes_lay_every_payload_out_as_rust_does() {
    let Some(python) =
        common::python::interpreter("python_ctypes_lay_every_payload_out_as_rust_does")
    else {
        return;
    };
    let ipc = common::Isolated::new("pyctypes");
    let json = layouts_json().to_string();
    let out = common::python::run_script(
        &python,
        &ipc,
        "python/tests/check_ctypes_layout.py",
        &[&json],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "check_ctypes_layout.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let checked = layouts_in_order().len();
    assert!(
        stdout.contains(&format!("{checked} structures match")),
        "{stdout}"
    );
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn python_finds_the_default_deployment_where_rins_puts_it() {
    let Some(python) =
        common::python::interpreter("python_finds_the_default_deployment_where_rins_puts_it")
    else {
        return;
    };
    let cases: Vec<serde_json::Value> = [
        (1000, Some("/run/user/1000")),
        (1000, Some("/run/user/1000/")),
        (1000, Some("")),
        (1000, None),
        (0, Some("/run/user/0")),
        (0, None),
        (10, None),
    ]
    .into_iter()
    .map(|(uid, xdg)| {
        serde_json::json!({
            "uid": uid,
            "xdg": xdg,
            "prefix": ipc::default_prefix(uid),
            "root": ipc::default_root(uid, xdg),
        })
    })
    .collect();
    let ipc = common::Isolated::new("pydefaults");
    let json = serde_json::Value::Array(cases).to_string();
    let out = common::python::run_script(&python, &ipc, "python/tests/check_defaults.py", &[&json]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("7 cases match"),
        "check_defaults.py:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
