//! A program's `param`s, set by the workcell: `[params]` for every program that declares
//! the name, `[robot.params]` for one robot (which wins). A value is checked against the
//! parameter's type and unit as the workcell's own values are (a number with its unit, an
//! integer, a bool); the robot's module gets the value as the parameter's initial value,
//! in a copy of the module (other robots running the same program keep theirs).

use std::collections::BTreeMap;
use std::sync::Arc;

use vworks_vm::{ConstValue, Module, Type};

use crate::context::Ctx;
use crate::error::CellError;

/// The `param`s `module` declares: name, type and default value, in declaration order.
pub fn declared(module: &Module) -> Vec<(String, Type, ConstValue)> {
    module
        .vars
        .iter()
        .filter(|v| v.param)
        .map(|v| (module.str(v.name).to_string(), v.ty, v.init.clone()))
        .collect()
}

fn listing(names: &[String]) -> String {
    if names.is_empty() {
        "it declares none (`param speed = 250mm/s;` at the top of a program declares one)".into()
    } else {
        format!("its params are {}", names.join(", "))
    }
}

/// The robot's module with its params set: `own` (the robot's `[robot.params]`, keys
/// under `key`) first, else `cell` (`[params]`). `program` names the module's file.
/// Robots whose params come out the same share one copy (`copies`).
pub(crate) fn apply(
    cx: &Ctx,
    key: &str,
    program: &str,
    module: Arc<Module>,
    own: &BTreeMap<String, toml::Value>,
    cell: &BTreeMap<String, toml::Value>,
    copies: &mut Vec<Arc<Module>>,
) -> Result<Arc<Module>, CellError> {
    let names: Vec<String> = declared(&module).into_iter().map(|d| d.0).collect();
    for name in own.keys() {
        if !names.contains(name) {
            return Err(cx.bad(
                &format!("{key}.params.{name}"),
                format!(
                    "`{program}` declares no param `{name}`; {}",
                    listing(&names)
                ),
            ));
        }
    }
    let mut patched: Option<Module> = None;
    for (i, v) in module.vars.iter().enumerate() {
        if !v.param {
            continue;
        }
        let name = module.str(v.name);
        let (value, at) = match (own.get(name), cell.get(name)) {
            (Some(x), _) => (x, format!("{key}.params.{name}")),
            (None, Some(x)) => (x, format!("params.{name}")),
            (None, None) => continue,
        };
        let new = value_of(cx, &at, value, v.ty, program, name)?;
        if new != v.init {
            let m = patched.get_or_insert_with(|| (*module).clone());
            m.vars[i].init = new;
        }
    }
    let Some(patched) = patched else {
        return Ok(module);
    };
    if let Some(same) = copies
        .iter()
        .find(|c| c.files == patched.files && c.vars == patched.vars)
    {
        return Ok(Arc::clone(same));
    }
    let patched = Arc::new(patched);
    copies.push(Arc::clone(&patched));
    Ok(patched)
}

/// Every `[params]` key must be a param of some program of the cell.
pub(crate) fn check_cell_params<'m>(
    cx: &Ctx,
    cell: &BTreeMap<String, toml::Value>,
    modules: impl Iterator<Item = &'m Arc<Module>>,
) -> Result<(), CellError> {
    let mut all: Vec<String> = modules
        .flat_map(|m| declared(m).into_iter().map(|d| d.0))
        .collect();
    all.sort();
    all.dedup();
    for name in cell.keys() {
        if !all.contains(name) {
            return Err(cx.bad(
                &format!("params.{name}"),
                format!(
                    "no program of the cell declares a param `{name}`; {}",
                    if all.is_empty() {
                        "they declare none (`param speed = 250mm/s;` at the top of a program declares one)".to_string()
                    } else {
                        format!("their params are {}", all.join(", "))
                    }
                ),
            ));
        }
    }
    Ok(())
}

/// A workcell value as a value of the parameter's type.
fn value_of(
    cx: &Ctx,
    at: &str,
    v: &toml::Value,
    ty: Type,
    program: &str,
    name: &str,
) -> Result<ConstValue, CellError> {
    match (ty, v) {
        (Type::Bool, toml::Value::Boolean(b)) => Ok(ConstValue::Bool(*b)),
        (Type::Int, toml::Value::Integer(i)) => Ok(ConstValue::Int(*i)),
        (Type::Int, toml::Value::Float(x)) if x.fract() == 0.0 && x.abs() < 9.0e15 => {
            Ok(ConstValue::Int(*x as i64))
        }
        (Type::Num(dim), _) if !matches!(v, toml::Value::Boolean(_)) => {
            Ok(ConstValue::Num(cx.quantity(v, dim, at)?))
        }
        _ => Err(cx.bad(
            at,
            format!(
                "`{name}` is {} in `{program}`; write {}",
                match ty {
                    Type::Num(d) => d.described(),
                    other => format!("{other}"),
                },
                match ty {
                    Type::Bool => "true or false",
                    Type::Int => "a whole number",
                    _ => "a number with its unit",
                }
            ),
        )),
    }
}
