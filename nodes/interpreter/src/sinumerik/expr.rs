//! Arithmetic of the 802D (`001` §9.1.6, §9.9.1; inventory §2.3): `+ - * /` with the usual
//! precedence, parentheses, the functions SIN COS TAN (degrees) ASIN ACOS ATAN2 SQRT POT ABS
//! TRUNC LN EXP, the comparisons `== <> > < >= <=` (1 fulfilled, 0 not) and, in MSG texts,
//! `<<` joining strings and numbers. The parser turns tokens into an [`Expr`]; evaluation asks
//! the front end for the variables' values.

use std::borrow::Cow;

use cnc_interpreter_core::Fault;

use super::lex::Tok;

/// A value: the arithmetic is numbers; strings live in STRING variables and MSG texts.
#[derive(Debug, Clone, PartialEq)]
pub enum Val {
    Num(f64),
    Str(String),
}

impl Val {
    pub fn num(&self) -> Result<f64, EvalError> {
        match self {
            Val::Num(v) => Ok(*v),
            Val::Str(s) => Err(EvalError::new(
                Fault::Macro,
                format!("string \"{s}\" where a number is needed"),
            )),
        }
    }

    /// As MSG shows it: numbers without trailing zeros.
    pub fn text(&self) -> String {
        match self {
            Val::Num(v) => cnc_interpreter_core::show(*v),
            Val::Str(s) => s.clone(),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct EvalError {
    pub fault: Fault,
    pub text: String,
}

impl EvalError {
    pub fn new(fault: Fault, text: impl Into<String>) -> EvalError {
        EvalError {
            fault,
            text: text.into(),
        }
    }
}

/// A value as written; names borrow from the block's line.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr<'s> {
    Num(f64),
    Str(&'s str),
    /// An arithmetic parameter by its number (`R12`).
    R(f64),
    /// A variable: `R` with a computed index (`R[R0]`), a user or system variable with its
    /// indexes (`PVAR5[2]`, `$AA_IW[X]`).
    Var(Cow<'s, str>, Vec<Expr<'s>>),
    /// An axis name as an index (`$AA_IW[X]`, `FXS[Z1]`).
    Axis(Cow<'s, str>),
    Neg(Box<Expr<'s>>),
    /// An operator and its two operands (one allocation for both).
    Bin(&'static str, Box<(Expr<'s>, Expr<'s>)>),
    Call(Cow<'s, str>, Vec<Option<Expr<'s>>>),
}

/// How evaluation reads a variable: its name and evaluated indexes.
pub type Reader<'r> = dyn Fn(&str, &[Val]) -> Result<Val, EvalError> + 'r;

/// A parser over one block's tokens.
pub struct Parser<'a, 's> {
    pub toks: &'a [Tok<'s>],
    pub at: usize,
    /// How deep the value being read nests (signs, parentheses, function arguments).
    depth: usize,
}

/// Deepest nesting of one value: a line of a thousand `(` is an alarm, not a stack overflow.
const MAX_NESTING: usize = 64;

type PResult<T> = Result<T, String>;

impl<'a, 's> Parser<'a, 's> {
    pub fn new(toks: &'a [Tok<'s>]) -> Parser<'a, 's> {
        Parser {
            toks,
            at: 0,
            depth: 0,
        }
    }

    pub fn peek(&self) -> Option<&'a Tok<'s>> {
        self.toks.get(self.at)
    }

    pub fn peek_at(&self, k: usize) -> Option<&'a Tok<'s>> {
        self.toks.get(self.at + k)
    }

    pub fn take(&mut self) -> Option<&'a Tok<'s>> {
        let t = self.toks.get(self.at);
        self.at += usize::from(t.is_some());
        t
    }

    pub fn is_op(&self, op: &str) -> bool {
        matches!(self.peek(), Some(Tok::Op(o)) if *o == op)
    }

    pub fn eat_op(&mut self, op: &str) -> bool {
        let yes = self.is_op(op);
        self.at += usize::from(yes);
        yes
    }

    pub fn expect_op(&mut self, op: &str) -> PResult<()> {
        if self.eat_op(op) {
            Ok(())
        } else {
            Err(match self.peek() {
                Some(t) => format!("'{op}' expected before '{t}'"),
                None => format!("'{op}' expected at the end of the block"),
            })
        }
    }

    /// An expression, comparisons and `<<` included.
    pub fn expr(&mut self) -> PResult<Expr<'s>> {
        let mut left = self.comparison()?;
        while self.eat_op("<<") {
            let right = self.comparison()?;
            left = Expr::Bin("<<", Box::new((left, right)));
        }
        Ok(left)
    }

    fn comparison(&mut self) -> PResult<Expr<'s>> {
        let left = self.sum()?;
        for op in ["==", "<>", "<=", ">=", "<", ">"] {
            if self.eat_op(op) {
                let right = self.sum()?;
                return Ok(Expr::Bin(op, Box::new((left, right))));
            }
        }
        Ok(left)
    }

    fn sum(&mut self) -> PResult<Expr<'s>> {
        let mut left = self.term()?;
        loop {
            let op = if self.eat_op("+") {
                "+"
            } else if self.eat_op("-") {
                "-"
            } else {
                return Ok(left);
            };
            let right = self.term()?;
            left = Expr::Bin(op, Box::new((left, right)));
        }
    }

    fn term(&mut self) -> PResult<Expr<'s>> {
        let mut left = self.unary()?;
        loop {
            let op = if self.eat_op("*") {
                "*"
            } else if self.eat_op("/") {
                "/"
            } else {
                return Ok(left);
            };
            let right = self.unary()?;
            left = Expr::Bin(op, Box::new((left, right)));
        }
    }

    /// Every nesting passes here (a sign, or a primary's parentheses and arguments).
    fn unary(&mut self) -> PResult<Expr<'s>> {
        if self.depth >= MAX_NESTING {
            return Err(format!("a value nested deeper than {MAX_NESTING} levels"));
        }
        self.depth += 1;
        let e = self.signed();
        self.depth -= 1;
        e
    }

    fn signed(&mut self) -> PResult<Expr<'s>> {
        if self.eat_op("-") {
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        if self.eat_op("+") {
            return self.unary();
        }
        self.primary()
    }

    fn primary(&mut self) -> PResult<Expr<'s>> {
        match self.take() {
            Some(Tok::Num(v)) => Ok(Expr::Num(*v)),
            Some(Tok::Str(s)) => Ok(Expr::Str(s)),
            Some(Tok::Op("(")) => {
                let e = self.expr()?;
                self.expect_op(")")?;
                Ok(e)
            }
            Some(Tok::Word {
                letter: 'R',
                value,
                digits,
                ..
            }) if !digits.is_empty() => Ok(Expr::R(*value)),
            Some(Tok::Name(n)) if n == "TRUE" => Ok(Expr::Num(1.0)),
            Some(Tok::Name(n)) if n == "FALSE" => Ok(Expr::Num(0.0)),
            Some(Tok::Name(n)) => {
                let name = n.clone();
                if self.is_op("(") {
                    let args = self.arguments()?;
                    Ok(Expr::Call(name, args))
                } else if self.is_op("[") {
                    let idx = self.indexes()?;
                    Ok(Expr::Var(name, idx))
                } else {
                    Ok(Expr::Var(name, Vec::new()))
                }
            }
            Some(t) => Err(format!("'{t}' cannot start a value")),
            None => Err("a value is missing at the end of the block".into()),
        }
    }

    /// `( a, , c )`: arguments, each may be left out.
    pub fn arguments(&mut self) -> PResult<Vec<Option<Expr<'s>>>> {
        self.expect_op("(")?;
        let mut args = Vec::new();
        if self.eat_op(")") {
            return Ok(args);
        }
        loop {
            if self.is_op(",") || self.is_op(")") {
                args.push(None);
            } else if let Some(axis) = self.axis_argument() {
                self.at += 1;
                args.push(Some(axis));
            } else {
                args.push(Some(self.expr()?));
            }
            if self.eat_op(")") {
                return Ok(args);
            }
            self.expect_op(",")?;
        }
    }

    /// An axis or spindle as an argument (`MASLDEF(AUX,S3)`, `PRESETON(Y1,0)`): a word
    /// alone between `(`, `,` and `)`, other than an R parameter.
    fn axis_argument(&self) -> Option<Expr<'s>> {
        match (self.peek(), self.peek_at(1)) {
            (Some(Tok::Word { letter, digits, .. }), Some(Tok::Op("," | ")")))
                if *letter != 'R' =>
            {
                Some(Expr::Axis(Cow::Owned(format!("{letter}{digits}"))))
            }
            _ => None,
        }
    }

    /// `[ i ]` or `[ i, j ]`; an axis name may be an index.
    pub fn indexes(&mut self) -> PResult<Vec<Expr<'s>>> {
        self.expect_op("[")?;
        let mut idx = Vec::new();
        loop {
            let axis = match (self.peek(), self.peek_at(1)) {
                (Some(Tok::Name(n)), Some(Tok::Op("]" | ","))) if n.len() == 1 => Some(n.clone()),
                (Some(Tok::Word { letter, digits, .. }), Some(Tok::Op("]" | ",")))
                    if *letter != 'R' =>
                {
                    Some(Cow::Owned(format!("{letter}{digits}")))
                }
                _ => None,
            };
            match axis {
                Some(a) => {
                    self.at += 1;
                    idx.push(Expr::Axis(a));
                }
                None => idx.push(self.expr()?),
            }
            if self.eat_op("]") {
                return Ok(idx);
            }
            self.expect_op(",")?;
        }
    }
}

/// Evaluates `e`, reading variables through `var` (name, evaluated indexes).
pub fn eval(e: &Expr, var: &Reader) -> Result<Val, EvalError> {
    Ok(match e {
        Expr::Num(v) => Val::Num(*v),
        Expr::Str(s) => Val::Str(s.to_string()),
        Expr::Axis(a) => Val::Str(a.to_string()),
        Expr::R(k) => var("R", &[Val::Num(*k)])?,
        // One or two indexes (every array the manual defines) are read without a list.
        Expr::Var(name, idx) => match idx.as_slice() {
            [] => var(name, &[])?,
            [i] => var(name, &[eval(i, var)?])?,
            [i, j] => var(name, &[eval(i, var)?, eval(j, var)?])?,
            _ => {
                let idx: Vec<Val> = idx.iter().map(|i| eval(i, var)).collect::<Result<_, _>>()?;
                var(name, &idx)?
            }
        },
        Expr::Neg(a) => Val::Num(-eval(a, var)?.num()?),
        Expr::Bin("<<", ab) => Val::Str(eval(&ab.0, var)?.text() + &eval(&ab.1, var)?.text()),
        Expr::Bin(op, ab) => {
            let (a, b) = (&ab.0, &ab.1);
            let (a, b) = (eval(a, var)?, eval(b, var)?);
            if let (Val::Str(x), Val::Str(y)) = (&a, &b) {
                return match *op {
                    "==" => Ok(Val::Num(f64::from(u8::from(x == y)))),
                    "<>" => Ok(Val::Num(f64::from(u8::from(x != y)))),
                    _ => Err(EvalError::new(Fault::Macro, format!("'{op}' on strings"))),
                };
            }
            let (a, b) = (a.num()?, b.num()?);
            let truth = |t: bool| f64::from(u8::from(t));
            Val::Num(match *op {
                "+" => a + b,
                "-" => a - b,
                "*" => a * b,
                "/" if b == 0.0 => {
                    return Err(EvalError::new(Fault::MacroDivide, "division by zero"))
                }
                "/" => a / b,
                "==" => truth((a - b).abs() < 1e-9),
                "<>" => truth((a - b).abs() >= 1e-9),
                "<" => truth(a < b),
                ">" => truth(a > b),
                "<=" => truth(a <= b),
                ">=" => truth(a >= b),
                _ => return Err(EvalError::new(Fault::Macro, format!("operator {op}"))),
            })
        }
        Expr::Call(name, args) => function(name, args, var)?,
    })
}

fn function(name: &str, args: &[Option<Expr>], var: &Reader) -> Result<Val, EvalError> {
    let want = if name == "ATAN2" { 2 } else { 1 };
    let known = [
        "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN2", "SQRT", "POT", "ABS", "TRUNC", "LN", "EXP",
    ];
    if !known.contains(&name) {
        return Err(EvalError::new(
            Fault::NoSuchAddress,
            format!("{name}() is no function of this control"),
        ));
    }
    if args.len() != want || args.iter().any(Option::is_none) {
        return Err(EvalError::new(
            Fault::MacroArgument,
            format!("{name}() takes {want} argument(s)"),
        ));
    }
    let mut v = [0.0; 2];
    for (slot, a) in v.iter_mut().zip(args.iter().flatten()) {
        *slot = eval(a, var)?.num()?;
    }
    let x = v[0];
    let domain = |ok: bool, r: f64| {
        if ok && r.is_finite() {
            Ok(r)
        } else {
            Err(EvalError::new(
                Fault::MacroArgument,
                format!(
                    "{name}({}) is outside its domain",
                    cnc_interpreter_core::show(x)
                ),
            ))
        }
    };
    let r = match name {
        "SIN" => x.to_radians().sin(),
        "COS" => x.to_radians().cos(),
        "TAN" => domain(true, x.to_radians().tan())?,
        "ASIN" => domain((-1.0..=1.0).contains(&x), x.asin().to_degrees())?,
        "ACOS" => domain((-1.0..=1.0).contains(&x), x.acos().to_degrees())?,
        "ATAN2" => x.atan2(v[1]).to_degrees(),
        "SQRT" => domain(x >= 0.0, x.sqrt())?,
        "POT" => domain(true, x * x)?,
        "ABS" => x.abs(),
        "TRUNC" => x.trunc(),
        "LN" => domain(x > 0.0, x.ln())?,
        _ => domain(true, x.exp())?,
    };
    Ok(Val::Num(r))
}

#[cfg(test)]
mod tests {
    use super::super::lex::tokens;
    use super::*;

    fn value(text: &str) -> f64 {
        let toks = tokens(text).unwrap();
        let mut p = Parser::new(&toks);
        let e = p.expr().unwrap();
        assert_eq!(p.at, toks.len(), "{text}");
        let r = |n: &str, i: &[Val]| match (n, i) {
            ("R", [Val::Num(k)]) => Ok(Val::Num(*k * 10.0)),
            _ => Err(EvalError::new(Fault::MacroVariable, n)),
        };
        eval(&e, &r).unwrap().num().unwrap()
    }

    #[test]
    fn precedence_functions_and_comparisons() {
        assert_eq!(value("R1*R2+R3"), 10.0 * 20.0 + 30.0);
        assert_eq!(value("R3+R2*R1"), 230.0);
        assert_eq!(value("-(2+3)*4"), -20.0);
        assert!((value("SIN(25.3)") - 0.427_358).abs() < 1e-6);
        assert!((value("ATAN2(30.5,80.1)") - 20.8455).abs() < 1e-4);
        assert!((value("ASIN(0.35)") - 20.487).abs() < 1e-3);
        assert_eq!(value("SQRT(POT(3)+POT(4))"), 5.0);
        assert_eq!(value("TRUNC(-2.7)"), -2.0);
        assert_eq!(value("R1 >= SIN(90)*10"), 1.0);
        assert_eq!(value("2 <> 2"), 0.0);
        assert_eq!(value("COS (60)"), 0.5000000000000001);
    }

    #[test]
    fn errors_name_their_fault() {
        let toks = tokens("1/(R1-10)").unwrap();
        let e = Parser::new(&toks).expr().unwrap();
        let r = |_: &str, i: &[Val]| Ok(Val::Num(i[0].num()? * 10.0));
        assert_eq!(eval(&e, &r).unwrap_err().fault, Fault::MacroDivide);
        let toks = tokens("SQRT(-1)").unwrap();
        let e = Parser::new(&toks).expr().unwrap();
        assert_eq!(eval(&e, &r).unwrap_err().fault, Fault::MacroArgument);
        assert!(Parser::new(&tokens("(1+2").unwrap()).expr().is_err());
        let deep = format!("{}1{}", "(".repeat(10_000), ")".repeat(10_000));
        assert!(Parser::new(&tokens(&deep).unwrap()).expr().is_err());
        assert!(Parser::new(&tokens(&"-".repeat(10_000)).unwrap())
            .expr()
            .is_err());
        let fine = format!("{}1{}", "(".repeat(40), ")".repeat(40));
        assert!(Parser::new(&tokens(&fine).unwrap()).expr().is_ok());
    }
}
