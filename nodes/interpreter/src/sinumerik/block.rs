//! One 802D block as the parser reads it (`001` §9.1.2–§9.1.6, §9.9–§9.11): the skip mark,
//! the block number (`N10`, main block `:50`), a label, then its items in the order written.
//! What an item means (an address, a variable, a keyword, a program) is the executor's
//! business; the parser only knows the shapes.

use std::borrow::Cow;

use super::expr::{Expr, Parser};
use super::lex::{strip_comment, tokens_into, Tok};

/// An item of a block; names and digits borrow from the line.
#[derive(Debug, Clone, PartialEq)]
pub enum Item<'s> {
    /// `X20`, `G1`, `X-12`: an address letter with a number.
    Word {
        letter: char,
        digits: &'s str,
        value: f64,
    },
    /// `R10=value`: an arithmetic parameter by its number.
    Param {
        number: f64,
        value: Expr<'s>,
    },
    /// `NAME=value`, `NAME[i]=value`, `I1=value`, `X=AC(5)`: an address given an expression
    /// or a variable written; the executor tells which.
    Assign {
        name: Cow<'s, str>,
        index: Vec<Expr<'s>>,
        value: Expr<'s>,
    },
    /// A bare name: a keyword (`CIP`, `TRANS`, `STOPRE`) or a program to call (`LRAHMEN7`).
    Name(Cow<'s, str>),
    /// `NAME(arguments)`: `MSG(…)`, a cycle.
    Call(Cow<'s, str>, Vec<Option<Expr<'s>>>),
    /// `PROC name`: the program names itself in its first block (`001` §9.11.1); `true`
    /// when a parameter list follows.
    Proc(Cow<'s, str>, bool),
    /// `GOTOF label` / `GOTOB label`, under a condition when it came with `IF`.
    Goto {
        condition: Option<Expr<'s>>,
        forward: bool,
        target: Cow<'s, str>,
    },
    Def(Def<'s>),
    /// `CALL NAME`: the cycle or program whose name the variable `NAME` holds (§9.1.6).
    Indirect(Cow<'s, str>),
}

/// `DEF type name[dims]=init, …` (§9.9.2).
#[derive(Debug, Clone, PartialEq)]
pub struct Def<'s> {
    /// BOOL, CHAR, INT, REAL or STRING.
    pub ty: &'static str,
    /// STRING[n]: the longest string.
    pub len: Option<usize>,
    pub vars: Vec<DefVar<'s>>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct DefVar<'s> {
    pub name: Cow<'s, str>,
    pub dims: Vec<usize>,
    pub init: Option<Expr<'s>>,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Block<'s> {
    pub skip: bool,
    /// `N` or `:` number.
    pub number: Option<u32>,
    pub label: Option<Cow<'s, str>>,
    pub items: Vec<Item<'s>>,
}

/// The data types of `DEF` (§9.9.2).
const TYPES: [&str; 5] = ["BOOL", "CHAR", "INT", "REAL", "STRING"];

/// Parses one line; an error is the syntax alarm's text.
pub fn parse(line: &str) -> Result<Block<'_>, String> {
    Buffers::default().parse(line)
}

/// The room of the last block's token and item lists, kept for the next: a program reads a
/// block per command, and these two lists were the front end's most frequent allocations.
#[derive(Debug, Default)]
pub struct Buffers {
    toks: Vec<Tok<'static>>,
    items: Vec<Item<'static>>,
}

impl Buffers {
    /// Parses one line into the kept lists.
    pub fn parse<'s>(&mut self, line: &'s str) -> Result<Block<'s>, String> {
        let mut toks = relabel(std::mem::take(&mut self.toks));
        let items = relabel(std::mem::take(&mut self.items));
        let block = tokens_into(strip_comment(line), &mut toks).and_then(|()| {
            let mut p = Parser::new(&toks);
            parse_tokens(&mut p, items)
        });
        self.toks = relabel(toks);
        block
    }

    /// Takes back a block's item list once the block has run.
    pub fn recycle(&mut self, block: Block<'_>) {
        self.items = relabel(block.items);
    }
}

/// An emptied list as a list of another lifetime with its room kept: the standard library
/// collects a vector's own iterator in place when the element's layout stays the same (the
/// unit test below watches that it still does).
fn relabel<T, U>(mut v: Vec<T>) -> Vec<U> {
    v.clear();
    v.into_iter().filter_map(|_| None).collect()
}

/// The block the parser's tokens make, its items in `items` (empty, its room reused).
fn parse_tokens<'s>(p: &mut Parser<'_, 's>, items: Vec<Item<'s>>) -> Result<Block<'s>, String> {
    let mut b = Block {
        skip: p.eat_op("/"),
        items,
        ..Block::default()
    };
    match p.peek() {
        Some(Tok::Word {
            letter: 'N', value, ..
        }) => {
            b.number = Some(block_number(*value)?);
            p.at += 1;
        }
        Some(Tok::Op(":")) => {
            p.at += 1;
            match p.take() {
                Some(Tok::Num(v)) => b.number = Some(block_number(*v)?),
                _ => return Err("a main block ':' needs its number".into()),
            }
        }
        _ => {}
    }
    if let (Some(Tok::Name(n)), Some(Tok::Op(":"))) = (p.peek(), p.peek_at(1)) {
        b.label = Some(n.clone());
        p.at += 2;
    }
    while p.peek().is_some() {
        let item = item(p)?;
        b.items.push(item);
    }
    Ok(b)
}

fn block_number(v: f64) -> Result<u32, String> {
    if v.fract() != 0.0 || !(0.0..=99_999_999.0).contains(&v) {
        return Err(format!("block number {v} is not 0…99999999"));
    }
    Ok(v as u32)
}

fn item<'s>(p: &mut Parser<'_, 's>) -> Result<Item<'s>, String> {
    let Some(t) = p.take() else {
        return Err("block ends early".into());
    };
    match t {
        Tok::Word {
            letter,
            digits,
            value,
        } => {
            if p.eat_op("=") {
                let expr = p.expr()?;
                if *letter == 'R' {
                    return Ok(Item::Param {
                        number: *value,
                        value: expr,
                    });
                }
                Ok(Item::Assign {
                    name: Cow::Owned(format!("{letter}{digits}")),
                    index: Vec::new(),
                    value: expr,
                })
            } else {
                Ok(Item::Word {
                    letter: *letter,
                    digits,
                    value: *value,
                })
            }
        }
        Tok::Name(n) => name_item(p, n.clone()),
        other => Err(format!("'{other}' cannot start a word")),
    }
}

fn name_item<'s>(p: &mut Parser<'_, 's>, n: Cow<'s, str>) -> Result<Item<'s>, String> {
    match n.as_ref() {
        "DEF" => return def(p).map(Item::Def),
        "IF" => {
            let condition = p.expr()?;
            let (forward, target) = goto(p)?;
            return Ok(Item::Goto {
                condition: Some(condition),
                forward,
                target,
            });
        }
        "PROC" => {
            let Some(Tok::Name(name)) = p.take() else {
                return Err("PROC needs the program's name".into());
            };
            let params = p.is_op("(");
            if params {
                // The list is not read: the executor refuses it; the block ends here.
                p.at = p.toks.len();
            }
            return Ok(Item::Proc(name.clone(), params));
        }
        "CALL" => {
            let Some(Tok::Name(name)) = p.take() else {
                return Err("CALL needs the variable that holds the name".into());
            };
            return Ok(Item::Indirect(name.clone()));
        }
        "GOTOF" | "GOTOB" => {
            p.at -= 1;
            let (forward, target) = goto(p)?;
            return Ok(Item::Goto {
                condition: None,
                forward,
                target,
            });
        }
        _ => {}
    }
    if p.eat_op("=") {
        let value = p.expr()?;
        return Ok(Item::Assign {
            name: n,
            index: Vec::new(),
            value,
        });
    }
    if p.is_op("[") {
        let index = p.indexes()?;
        p.expect_op("=")?;
        let value = p.expr()?;
        return Ok(Item::Assign {
            name: n,
            index,
            value,
        });
    }
    if p.is_op("(") {
        let args = p.arguments()?;
        return Ok(Item::Call(n, args));
    }
    // `X-12`, `X .5`: a one-letter address and its number with blanks or a sign between.
    if n.len() == 1 {
        let neg = p.is_op("-");
        let sign = usize::from(neg || p.is_op("+"));
        if let Some(Tok::Num(v)) = p.peek_at(sign) {
            p.at += sign + 1;
            let letter = n.chars().next().unwrap_or('?');
            return Ok(Item::Word {
                letter,
                digits: "",
                value: if neg { -v } else { *v },
            });
        }
    }
    Ok(Item::Name(n))
}

fn goto<'s>(p: &mut Parser<'_, 's>) -> Result<(bool, Cow<'s, str>), String> {
    let forward = match p.take() {
        Some(Tok::Name(g)) if g == "GOTOF" => true,
        Some(Tok::Name(g)) if g == "GOTOB" => false,
        _ => return Err("IF needs GOTOF or GOTOB and a jump target".into()),
    };
    let target = match p.take() {
        Some(Tok::Name(l)) => l.clone(),
        Some(Tok::Word {
            letter: 'N',
            digits,
            ..
        }) => Cow::Owned(format!("N{}", digits.trim_start_matches('0'))),
        _ => return Err("a jump needs its target: a label or a block number".into()),
    };
    Ok((forward, target))
}

fn def<'s>(p: &mut Parser<'_, 's>) -> Result<Def<'s>, String> {
    let ty = match p.take() {
        Some(Tok::Name(t)) => TYPES.iter().copied().find(|ty| *ty == t.as_ref()),
        _ => None,
    }
    .ok_or("DEF needs a type: BOOL, CHAR, INT, REAL or STRING")?;
    let mut len = None;
    if ty == "STRING" {
        p.expect_op("[")?;
        len = match p.take() {
            Some(Tok::Num(v)) if *v >= 1.0 && v.fract() == 0.0 && *v <= 200.0 => Some(*v as usize),
            _ => return Err("STRING[n] needs its length n".into()),
        };
        p.expect_op("]")?;
    }
    let mut vars = Vec::new();
    loop {
        let name = match p.take() {
            Some(Tok::Name(n)) => n.clone(),
            Some(t) => return Err(format!("'{t}' is no variable name (two letters first)")),
            None => return Err("DEF needs a variable name".into()),
        };
        let mut dims = Vec::new();
        if p.eat_op("[") {
            loop {
                match p.take() {
                    Some(Tok::Num(v)) if *v >= 1.0 && v.fract() == 0.0 && *v <= 65_535.0 => {
                        dims.push(*v as usize)
                    }
                    _ => return Err(format!("array {name} needs whole dimensions ≥ 1")),
                }
                if p.eat_op("]") {
                    break;
                }
                p.expect_op(",")?;
            }
            if dims.len() > 2 {
                return Err(format!("array {name}: at most two dimensions"));
            }
        }
        let init = if p.eat_op("=") { Some(p.expr()?) } else { None };
        vars.push(DefVar { name, dims, init });
        if p.peek().is_none() {
            return Ok(Def { ty, len, vars });
        }
        p.expect_op(",")?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_lists_keep_their_room_and_a_block_reads_the_same_through_them() {
        let mut room = Buffers::default();
        let text = String::from("N10 G1 X=R2*SIN(R1)+R6 Y20 F100");
        let first = room.parse(&text).unwrap();
        assert_eq!(first, parse(&text).unwrap());
        let items = first.items.capacity();
        room.recycle(first);
        let toks = room.toks.capacity();
        assert!(
            items >= 4 && toks >= 10,
            "room {items} items, {toks} tokens"
        );
        // The next line, of another lifetime, reads into the same room.
        let next = String::from("R1=R1+1");
        let b = room.parse(&next).unwrap();
        assert_eq!(b, parse(&next).unwrap());
        assert_eq!(b.items.capacity(), items);
        room.recycle(b);
        assert_eq!(room.toks.capacity(), toks);
        // A line in error leaves the room usable.
        assert!(room.parse("X10 ?").is_err());
        assert_eq!(room.parse("G0 X1").unwrap(), parse("G0 X1").unwrap());
    }

    #[test]
    fn numbers_labels_and_items() {
        let b = parse("/N90 X118 Z180 ; skip").unwrap();
        assert!(b.skip);
        assert_eq!(b.number, Some(90));
        assert_eq!(b.items.len(), 2);
        let b = parse(":50 G54 F4.7").unwrap();
        assert_eq!(b.number, Some(50));
        let b = parse("N20 MA1: G0 Z=R2*COS (R1)+R5").unwrap();
        assert_eq!(b.label.as_deref(), Some("MA1"));
        assert!(matches!(&b.items[1], Item::Assign { name, .. } if name == "Z"));
        let b = parse("N40 IF R4 > 0 GOTOB MA1").unwrap();
        assert!(
            matches!(&b.items[0], Item::Goto { forward: false, target, condition: Some(_) } if target == "MA1")
        );
        let b = parse("R[R0]=5 I1=40 X-12").unwrap();
        assert!(
            matches!(&b.items[0], Item::Assign { name, index, .. } if name == "R" && index.len() == 1)
        );
        assert!(matches!(&b.items[1], Item::Assign { name, .. } if name == "I1"));
        assert_eq!(
            b.items[2],
            Item::Word {
                letter: 'X',
                digits: "",
                value: -12.0
            }
        );
        let b = parse("R12=R[R0]+1").unwrap();
        assert!(matches!(&b.items[0], Item::Param { number, .. } if *number == 12.0));
    }

    #[test]
    fn definitions() {
        let b = parse("DEF INT PVAR1, PVAR2, PVAR3=12, PVAR4").unwrap();
        let Item::Def(d) = &b.items[0] else { panic!() };
        assert_eq!(d.vars.len(), 4);
        assert!(d.vars[2].init.is_some());
        let b = parse("DEF STRING[12] PVAR=\"Hallo\"").unwrap();
        let Item::Def(d) = &b.items[0] else { panic!() };
        assert_eq!(d.len, Some(12));
        let b = parse("DEF REAL B[2,3]").unwrap();
        let Item::Def(d) = &b.items[0] else { panic!() };
        assert_eq!(d.vars[0].dims, [2, 3]);
        assert!(parse("DEF FLOAT X1").is_err());
        assert!(parse("DEF REAL A[0]").is_err());
    }
}
