//! ROS 2 message definitions: the `ros2msg` text a bag carries for each type (MCAP's
//! schema record, rosbag2's `message_definitions` table: the type's own fields, then
//! each type it uses after a line of `=` and `MSG: pkg/Type`), parsed into the types
//! whose CDR encoding [`super::cdr`] decodes.

use std::collections::HashMap;

/// A primitive type of the ROS 2 interface definition language.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Prim {
    Bool,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Str,
}

impl Prim {
    fn parse(name: &str) -> Option<Self> {
        // `string<=N`: a bounded string is encoded as a string
        let name = name.split("<=").next().unwrap_or(name);
        Some(match name {
            "bool" => Prim::Bool,
            "int8" => Prim::I8,
            "uint8" | "byte" | "char" => Prim::U8,
            "int16" => Prim::I16,
            "uint16" => Prim::U16,
            "int32" => Prim::I32,
            "uint32" => Prim::U32,
            "int64" => Prim::I64,
            "uint64" => Prim::U64,
            "float32" => Prim::F32,
            "float64" => Prim::F64,
            "string" => Prim::Str,
            _ => return None,
        })
    }

    /// An unsigned byte: a sequence of these is read as bytes.
    pub(crate) fn is_byte(self) -> bool {
        self == Prim::U8
    }
}

/// A field's element type: a primitive or a message (an index into [`Types`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Elem {
    Prim(Prim),
    Msg(usize),
}

/// One value, a fixed-size array (`T[N]`) or a sequence (`T[]`, `T[<=N]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    One,
    Array(usize),
    Sequence,
}

#[derive(Debug, Clone)]
pub(crate) struct Field {
    pub(crate) name: String,
    pub(crate) elem: Elem,
    pub(crate) shape: Shape,
}

/// A message type: `pkg/Name` and its fields in wire order.
#[derive(Debug, Clone)]
pub(crate) struct MsgType {
    pub(crate) name: String,
    pub(crate) fields: Vec<Field>,
}

/// The types of one topic: its own (index 0) and every type it uses.
#[derive(Debug, Clone)]
pub(crate) struct Types {
    pub(crate) types: Vec<MsgType>,
}

/// `pkg/msg/Name`, `pkg/Name` -> `pkg/Name`.
pub(crate) fn normalise(name: &str) -> String {
    let parts: Vec<&str> = name.split('/').filter(|p| !p.is_empty()).collect();
    match parts.as_slice() {
        [pkg, "msg", ty] => format!("{pkg}/{ty}"),
        _ => parts.join("/"),
    }
}

/// A field line's type token resolved: a primitive or `pkg/Name` (a bare `Name` is in
/// the package `pkg` of the type that uses it; `Header` is std_msgs', as in ROS 1).
fn resolve(token: &str, pkg: &str) -> Result<(Option<Prim>, String), String> {
    if let Some(p) = Prim::parse(token) {
        return Ok((Some(p), String::new()));
    }
    if token.starts_with("wstring") {
        return Err("wstring fields are not read (a UTF-16 string no navigation message uses)".into());
    }
    Ok((
        None,
        if token.contains('/') {
            normalise(token)
        } else if token == "Header" {
            "std_msgs/Header".into()
        } else {
            format!("{pkg}/{token}")
        },
    ))
}

/// The fields of one section of a definition, with their type names unresolved.
type Section = Vec<(String, Option<Prim>, String, Shape)>;

fn parse_section(text: &str, pkg: &str, type_name: &str) -> Result<Section, String> {
    let mut fields = Vec::new();
    for line in text.lines() {
        let mut tokens = line.split_whitespace();
        let Some(ty) = tokens.next().filter(|t| !t.starts_with('#')) else { continue };
        let rest = line.trim_start()[ty.len()..].trim_start();
        let name: String = rest.chars().take_while(|c| !c.is_whitespace() && *c != '=' && *c != '#').collect();
        if name.is_empty() {
            return Err(format!("{type_name}: the line `{}` has a type and no field name", line.trim()));
        }
        if rest[name.len()..].trim_start().starts_with('=') {
            continue; // a constant: not on the wire
        }
        let (base, shape) = match ty.find('[') {
            None => (ty, Shape::One),
            Some(i) => {
                let inner =
                    ty[i + 1..].strip_suffix(']').ok_or_else(|| format!("{type_name}: bad array type `{ty}`"))?;
                let shape = if inner.is_empty() || inner.starts_with("<=") {
                    Shape::Sequence
                } else {
                    Shape::Array(inner.parse().map_err(|_| format!("{type_name}: bad array length in `{ty}`"))?)
                };
                (&ty[..i], shape)
            }
        };
        let (prim, msg) = resolve(base, pkg).map_err(|m| format!("{type_name}.{name}: {m}"))?;
        fields.push((name, prim, msg, shape));
    }
    Ok(fields)
}

impl Types {
    /// The types of `type_name` (`pkg/msg/Name`) from the `ros2msg` text `definition`,
    /// with `known` (standard definitions) for the types the text does not hold (all of
    /// them without a text).
    pub(crate) fn parse(
        type_name: &str,
        definition: Option<&str>,
        known: &dyn Fn(&str) -> Option<&'static str>,
    ) -> Result<Self, String> {
        let main = normalise(type_name);
        let mut sections: HashMap<String, String> = HashMap::new();
        let mut current = (main.clone(), String::new());
        for line in definition.unwrap_or("").lines() {
            if line.len() >= 3 && line.trim().chars().all(|c| c == '=') {
                continue;
            }
            if let Some(name) = line.trim().strip_prefix("MSG:") {
                let done = std::mem::replace(&mut current, (normalise(name.trim()), String::new()));
                sections.entry(done.0).or_insert(done.1);
                continue;
            }
            current.1.push_str(line);
            current.1.push('\n');
        }
        if definition.is_some() {
            sections.entry(current.0).or_insert(current.1);
        }
        let mut types = Types { types: Vec::new() };
        let mut index: HashMap<String, usize> = HashMap::new();
        types.add(&main, &sections, known, &mut index, &mut Vec::new())?;
        Ok(types)
    }

    fn add(
        &mut self,
        name: &str,
        sections: &HashMap<String, String>,
        known: &dyn Fn(&str) -> Option<&'static str>,
        index: &mut HashMap<String, usize>,
        visiting: &mut Vec<String>,
    ) -> Result<usize, String> {
        if let Some(&i) = index.get(name) {
            return Ok(i);
        }
        if visiting.iter().any(|v| v == name) {
            return Err(format!(
                "{name} contains itself ({} -> {name}): such a message has no end",
                visiting.join(" -> ")
            ));
        }
        let text = match sections.get(name) {
            Some(t) => t.clone(),
            None => known(name).map(String::from).ok_or_else(|| {
                format!("no definition of {name}: the bag does not carry it and it is not a standard message onebeacon knows")
            })?,
        };
        let pkg = name.split('/').next().unwrap_or("");
        let section = parse_section(&text, pkg, name)?;
        // the type's place first, so that the topic's own is the first
        let i = self.types.len();
        self.types.push(MsgType { name: name.to_string(), fields: Vec::new() });
        visiting.push(name.to_string());
        let mut fields = Vec::new();
        for (fname, prim, msg, shape) in section {
            let elem = match prim {
                Some(p) => Elem::Prim(p),
                None => Elem::Msg(self.add(&msg, sections, known, index, visiting)?),
            };
            fields.push(Field { name: fname, elem, shape });
        }
        visiting.pop();
        // an empty message is one byte on the wire (rosidl's structure_needs_at_least_one_member)
        if fields.is_empty() {
            fields.push(Field {
                name: "structure_needs_at_least_one_member".into(),
                elem: Elem::Prim(Prim::U8),
                shape: Shape::One,
            });
        }
        self.types[i].fields = fields;
        index.insert(name.to_string(), i);
        Ok(i)
    }

    /// The field path `path` (`pose.pose.position.x`, `ranges[2]`) of the topic's type:
    /// the steps to take in a decoded message, and the type it ends on.
    pub(crate) fn path(&self, path: &str) -> Result<(Vec<Step>, Leaf), String> {
        // a quaternion's roll, pitch or yaw (`orientation.roll`): a quaternion has no
        // field of these names
        if let Some((head, angle)) = path.rsplit_once('.')
            && let Ok((steps, Leaf::Yaw)) = self.path(head)
        {
            match angle {
                "roll" => return Ok((steps, Leaf::Roll)),
                "pitch" => return Ok((steps, Leaf::Pitch)),
                "yaw" => return Ok((steps, Leaf::Yaw)),
                _ => {}
            }
        }
        let mut steps = Vec::new();
        let mut at = (Elem::Msg(0), Shape::One);
        for part in path.split('.') {
            let (name, indices) = match part.find('[') {
                Some(i) => (&part[..i], &part[i..]),
                None => (part, ""),
            };
            let Elem::Msg(t) = at.0 else {
                return Err(format!("`{name}`: a {} has no fields", self.elem_name(at.0)));
            };
            if at.1 != Shape::One {
                return Err(format!("`{name}`: an array of {} needs an index first ([0])", self.types[t].name));
            }
            let ty = &self.types[t];
            let Some(f) = ty.fields.iter().position(|f| f.name == name) else {
                let names: Vec<&str> = ty.fields.iter().map(|f| f.name.as_str()).collect();
                return Err(format!("no field `{name}` in {} (its fields: {})", ty.name, names.join(", ")));
            };
            steps.push(Step::Field(f));
            at = (ty.fields[f].elem, ty.fields[f].shape);
            let mut rest = indices;
            while let Some(r) = rest.strip_prefix('[') {
                let (n, tail) = r.split_once(']').ok_or_else(|| format!("bad index in `{part}`"))?;
                let n: usize = n.parse().map_err(|_| format!("bad index `{n}` in `{part}`: a non-negative integer"))?;
                if at.1 == Shape::One {
                    return Err(format!("`{name}` is not an array: no index [{n}]"));
                }
                if let Shape::Array(len) = at.1
                    && n >= len
                {
                    return Err(format!("`{part}`: index {n} beyond its {len} elements"));
                }
                steps.push(Step::Index(n));
                at.1 = Shape::One;
                rest = tail;
            }
        }
        if at.1 != Shape::One {
            return Err(format!("`{path}` is an array: name one element ({path}[0])"));
        }
        let leaf = match at.0 {
            Elem::Prim(Prim::Str) => Leaf::Text,
            Elem::Prim(_) => Leaf::Number,
            Elem::Msg(t) => {
                let names: Vec<&str> = self.types[t].fields.iter().map(|f| f.name.as_str()).collect();
                let is = |want: &[&str]| names == want;
                if is(&["sec", "nanosec"]) {
                    Leaf::Time
                } else if is(&["x", "y", "z", "w"]) {
                    Leaf::Yaw
                } else {
                    return Err(format!(
                        "`{path}` is a {} (fields: {}); a number, a text, a time (sec, nanosec) or a quaternion (its yaw, or `.roll`, `.pitch`) is read",
                        self.types[t].name,
                        names.join(", ")
                    ));
                }
            }
        };
        Ok((steps, leaf))
    }

    fn elem_name(&self, e: Elem) -> String {
        match e {
            Elem::Prim(p) => format!("{p:?}").to_lowercase(),
            Elem::Msg(t) => self.types[t].name.clone(),
        }
    }

    /// Whether the topic's type has a `header` of std_msgs/Header.
    pub(crate) fn has_header(&self) -> bool {
        self.types[0]
            .fields
            .iter()
            .any(|f| f.name == "header" && matches!(f.elem, Elem::Msg(t) if self.types[t].name == "std_msgs/Header"))
    }
}

/// One step of a field path in a decoded message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step {
    Field(usize),
    Index(usize),
}

/// What a field path ends on, and how it is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Leaf {
    Number,
    Text,
    /// builtin_interfaces/Time or Duration: seconds.
    Time,
    /// A quaternion: its yaw, rad, about the frame's z axis; or its roll or pitch (the
    /// path's `.roll`, `.pitch`): ZYX Euler angles.
    Yaw,
    Roll,
    Pitch,
}

#[cfg(test)]
mod tests {
    use super::*;

    const ODOMETRY: &str = "std_msgs/Header header\nstring child_frame_id # the body\ngeometry_msgs/PoseWithCovariance pose\n\
        geometry_msgs/TwistWithCovariance twist\n";

    fn none(_: &str) -> Option<&'static str> {
        None
    }

    #[test]
    fn a_definition_and_the_types_it_uses_are_parsed() {
        let text = format!(
            "{ODOMETRY}================================================================================\nMSG: std_msgs/Header\n\
             builtin_interfaces/Time stamp\nstring frame_id\n=====\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n\
             ====\nMSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n====\nMSG: geometry_msgs/Pose\n\
             Point position\nQuaternion orientation\n===\nMSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n\
             ===\nMSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n===\n\
             MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n===\nMSG: geometry_msgs/Twist\n\
             Vector3 linear\nVector3 angular\n===\nMSG: geometry_msgs/Vector3\nint8 KIND=3\nfloat64 x\nfloat64 y\nfloat64 z\n"
        );
        let t = Types::parse("nav_msgs/msg/Odometry", Some(&text), &none).unwrap();
        assert_eq!(t.types[0].name, "nav_msgs/Odometry");
        assert!(t.has_header());
        let (steps, leaf) = t.path("pose.pose.position.y").unwrap();
        assert_eq!(steps, vec![Step::Field(2), Step::Field(0), Step::Field(0), Step::Field(1)]);
        assert_eq!(leaf, Leaf::Number);
        assert_eq!(t.path("pose.pose.orientation").unwrap().1, Leaf::Yaw);
        assert_eq!(t.path("pose.pose.orientation.pitch").unwrap().1, Leaf::Pitch);
        let e = t.path("pose.pose.orientation.tilt").unwrap_err();
        assert!(e.contains("no field `tilt`"), "{e}");
        assert_eq!(t.path("header.stamp").unwrap().1, Leaf::Time);
        assert_eq!(t.path("header.frame_id").unwrap().1, Leaf::Text);
        assert_eq!(t.path("pose.covariance[35]").unwrap().0.last(), Some(&Step::Index(35)));
        // the constant KIND is not a field
        let e = t.path("twist.twist.linear.KIND").unwrap_err();
        assert!(e.contains("no field `KIND` in geometry_msgs/Vector3 (its fields: x, y, z)"), "{e}");
        assert!(t.path("pose.covariance[36]").unwrap_err().contains("beyond its 36"));
        assert!(t.path("pose.covariance").unwrap_err().contains("is an array"));
        assert!(t.path("pose.pose").unwrap_err().contains("is a geometry_msgs/Pose"));
        let e = Types::parse("nav_msgs/msg/Odometry", Some(ODOMETRY), &none).unwrap_err();
        assert!(e.contains("no definition of std_msgs/Header"), "{e}");
    }

    #[test]
    fn a_type_that_uses_itself_is_refused() {
        let e = Types::parse("a/msg/A", Some("B b\n===\nMSG: a/B\nA a\n"), &none).unwrap_err();
        assert!(e.contains("a/A contains itself (a/A -> a/B -> a/A)"), "{e}");
    }
}
