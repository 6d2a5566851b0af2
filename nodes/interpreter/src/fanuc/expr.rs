//! Macro expressions (`000` §5.27.4–5.27.5): numbers, `#` variables, operators and functions.
//!
//! A value is `Option<f64>`: `None` is the null variable `#0` ("空变量"), with the manual's null
//! rules (§5.27.3): in arithmetic null counts as 0, in `==`/`!=` null differs from 0, in
//! `<`/`<=`/`>`/`>=` null counts as 0 (decision D10).

use cnc_interpreter_core::Fault;
pub use cnc_interpreter_core::Value;

#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number; `point` records whether it was written with a decimal point, which decides
    /// the unit of words given in least-input increments (decision D12).
    Num {
        value: f64,
        point: bool,
    },
    /// `#n`, `#[expr]`, `##n`.
    Var(Box<Expr>),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    Call(Func, Vec<Expr>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Not,
    BitNot,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Mul,
    Div,
    Add,
    Sub,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    BitOr,
    BitXor,
    BitAnd,
}

impl BinOp {
    /// Binding strength, as printed in `000` §5.27.5: `* /` before `+ -` before relations
    /// before `&& ||` before the bitwise operators, which bind loosest (decision D11).
    pub fn precedence(self) -> u8 {
        use BinOp::*;
        match self {
            Mul | Div => 5,
            Add | Sub => 4,
            Eq | Ne | Gt | Ge | Lt | Le => 3,
            And | Or => 2,
            BitOr | BitXor | BitAnd => 1,
        }
    }
}

/// The functions of `000` §5.27.4, with their short forms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Abs,
    Round,
    Int,
    Fix,
    Fup,
    Ln,
    Exp,
    Pow,
    Pi,
}

impl Func {
    pub fn from_name(name: &str) -> Option<Func> {
        use Func::*;
        Some(match name {
            "SIN" | "SI" => Sin,
            "COS" | "CO" => Cos,
            "TAN" | "TA" => Tan,
            "ASIN" | "AS" => Asin,
            "ACOS" | "AC" => Acos,
            "ATAN" | "AT" => Atan,
            "SQRT" | "SQ" => Sqrt,
            "ABS" | "AB" => Abs,
            "ROUND" | "RO" => Round,
            "INT" | "IN" => Int,
            "FIX" | "FI" => Fix,
            "FUP" | "FU" => Fup,
            "LN" => Ln,
            "EXP" | "EX" => Exp,
            "POW" | "PO" => Pow,
            "PI" => Pi,
            _ => return None,
        })
    }

    /// Number of bracketed arguments: `ATAN[a][b]`, `POW[a][b]`, `PI` none.
    pub fn arity(self) -> usize {
        match self {
            Func::Atan | Func::Pow => 2,
            Func::Pi => 0,
            _ => 1,
        }
    }
}

/// Why an expression could not be evaluated, and the fault the interpreter raises for it
/// (alarm 20 on Huaxing; FANUC tells them apart).
#[derive(Debug, Clone, PartialEq)]
pub struct EvalError(pub String, pub Fault);

/// Reads and writes macro variables for the evaluator.
pub trait Variables {
    fn read(&self, number: i64) -> Result<Value, EvalError>;
    /// Decimal places ROUND keeps: 3 on Huaxing (`000` §5.27.4); FANUC's ROUND in an
    /// expression rounds to a whole number (`003` inventory A.3).
    fn round_decimals(&self) -> i32 {
        3
    }
}

/// Rounds half away from zero to `decimals` places (ROUND keeps 3 decimals, §5.27.4).
pub fn round_half_away(x: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    let y = (x.abs() * scale + 0.5 + 1e-9).floor() / scale;
    y.copysign(x)
}

/// The variable number an index value names: must be a whole number.
pub fn variable_number(v: f64) -> Result<i64, EvalError> {
    let r = v.round();
    if (v - r).abs() > 1e-6 || r.abs() > 1e9 {
        return Err(EvalError(
            format!("variable number {v} is not a whole number"),
            Fault::MacroVariable,
        ));
    }
    Ok(r as i64)
}

impl Expr {
    pub fn num(value: f64) -> Expr {
        Expr::Num { value, point: true }
    }

    pub fn eval(&self, vars: &dyn Variables) -> Result<Value, EvalError> {
        Ok(match self {
            Expr::Num { value, .. } => Some(*value),
            Expr::Var(index) => {
                let n = index.eval(vars)?.ok_or_else(|| {
                    EvalError("variable number is null".into(), Fault::MacroVariable)
                })?;
                vars.read(variable_number(n)?)?
            }
            Expr::Unary(op, a) => {
                let a = a.eval(vars)?;
                match op {
                    UnOp::Neg => a.map(|v| -v),
                    UnOp::Not => Some(if truth(a) { 0.0 } else { 1.0 }),
                    UnOp::BitNot => Some(!(a.unwrap_or(0.0) as i64) as f64),
                }
            }
            Expr::Binary(op, a, b) => binary(*op, a.eval(vars)?, b.eval(vars)?)?,
            Expr::Call(f, args) => {
                let mut v = [0.0; 2];
                for (slot, a) in v.iter_mut().zip(args) {
                    *slot = a.eval(vars)?.unwrap_or(0.0);
                }
                Some(call(*f, v[0], v[1], vars.round_decimals())?)
            }
        })
    }

    /// Whether the expression is a plain number written with a decimal point.
    pub fn has_point(&self) -> bool {
        match self {
            Expr::Num { point, .. } => *point,
            Expr::Unary(UnOp::Neg, a) => a.has_point(),
            // A computed value is a value in mm, like a number with a point.
            _ => true,
        }
    }
}

/// Condition truth: non-zero is true, null is false.
pub fn truth(v: Value) -> bool {
    v.is_some_and(|x| x != 0.0)
}

fn bool_value(b: bool) -> Value {
    Some(if b { 1.0 } else { 0.0 })
}

fn binary(op: BinOp, a: Value, b: Value) -> Result<Value, EvalError> {
    use BinOp::*;
    let (x, y) = (a.unwrap_or(0.0), b.unwrap_or(0.0));
    let int = |v: f64| v as i64;
    Ok(match op {
        Add => Some(x + y),
        Sub => Some(x - y),
        Mul => Some(x * y),
        Div => {
            if y == 0.0 {
                return Err(EvalError("division by zero".into(), Fault::MacroDivide));
            }
            Some(x / y)
        }
        Eq => bool_value(a == b),
        Ne => bool_value(a != b),
        Gt => bool_value(x > y),
        Ge => bool_value(x >= y),
        Lt => bool_value(x < y),
        Le => bool_value(x <= y),
        And => bool_value(truth(a) && truth(b)),
        Or => bool_value(truth(a) || truth(b)),
        BitOr => Some((int(x) | int(y)) as f64),
        BitXor => Some((int(x) ^ int(y)) as f64),
        BitAnd => Some((int(x) & int(y)) as f64),
    })
}

fn call(f: Func, a: f64, b: f64, round_decimals: i32) -> Result<f64, EvalError> {
    use Func::*;
    let domain = |ok: bool, what: &str| {
        if ok {
            Ok(())
        } else {
            Err(EvalError(
                format!("{what} outside its domain"),
                Fault::MacroArgument,
            ))
        }
    };
    let v = match f {
        Sin => a.to_radians().sin(),
        Cos => a.to_radians().cos(),
        Tan => {
            domain(a.to_radians().cos().abs() > 1e-12, "TAN")?;
            a.to_radians().tan()
        }
        Asin => {
            domain((-1.0..=1.0).contains(&a), "ASIN")?;
            a.asin().to_degrees()
        }
        Acos => {
            domain((-1.0..=1.0).contains(&a), "ACOS")?;
            a.acos().to_degrees()
        }
        Atan => {
            let d = a.atan2(b).to_degrees();
            if d < 0.0 {
                d + 360.0
            } else {
                d
            }
        }
        Sqrt => {
            domain(a >= 0.0, "SQRT")?;
            a.sqrt()
        }
        Abs => a.abs(),
        Round => round_half_away(a, round_decimals),
        Int => round_half_away(a, 0),
        Fix => a.trunc(),
        Fup => {
            if a.fract() == 0.0 {
                a
            } else {
                a.trunc() + a.signum()
            }
        }
        Ln => {
            domain(a > 0.0, "LN")?;
            a.ln()
        }
        Exp => a.exp(),
        Pow => a.powf(b),
        Pi => std::f64::consts::PI,
    };
    if !v.is_finite() {
        return Err(EvalError(
            format!("{f:?} gives no finite number"),
            Fault::MacroArgument,
        ));
    }
    Ok(v)
}
