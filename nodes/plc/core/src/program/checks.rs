//! The whole program's checks once every line is read: its structure (levels, rungs,
//! subprograms), the logic stack's depth at every step, and the calls (targets, depth, no
//! recursion). A program that fails any is refused whole.

use super::*;

impl Program {
    /// END1 then END2 once each; subroutines only after END2, each SP closed by SPE; labels
    /// unique in their scope and jumps within it.
    pub(super) fn check_structure(&mut self) -> Result<(), LoadError> {
        let last_line = self.steps.last().map(|s| s.line).unwrap_or(1);
        let err = |line: u32, reason: String| LoadError { line, reason };
        let mut end1 = None;
        let mut end2 = None;
        let mut end3 = None;
        let mut open_sp: Option<(u16, u32)> = None;
        let mut scope = 0usize;
        self.scope = Vec::with_capacity(self.steps.len());
        for (i, s) in self.steps.iter().enumerate() {
            let line = s.line;
            if end3.is_some() {
                return Err(err(line, "instruction after END3".into()));
            }
            match s.instr {
                Instr::End1 if end1.is_some() => return Err(err(line, "second END1".into())),
                Instr::End1 => {
                    end1 = Some(i);
                    scope = i + 1;
                }
                Instr::End2 if end1.is_none() => return Err(err(line, "END2 before END1".into())),
                Instr::End2 if end2.is_some() => return Err(err(line, "second END2".into())),
                Instr::End2 => {
                    end2 = Some(i);
                    scope = i + 1;
                }
                Instr::End3 if open_sp.is_some() => {
                    return Err(err(line, "END3 inside a subroutine".into()))
                }
                Instr::End3 => end3 = Some(i),
                Instr::Sp(_) if end2.is_none() => {
                    return Err(err(line, "subroutines (SP) come after END2".into()))
                }
                Instr::Sp(_) if open_sp.is_some() => {
                    return Err(err(
                        line,
                        "SP inside a subroutine: close it with SPE".into(),
                    ))
                }
                Instr::Sp(n) => {
                    if self.subroutines.insert(n, i + 1).is_some() {
                        return Err(err(line, format!("subroutine P{n} defined twice")));
                    }
                    open_sp = Some((n, line));
                    scope = i + 1;
                }
                Instr::Spe if open_sp.is_none() => return Err(err(line, "SPE without SP".into())),
                Instr::Spe => open_sp = None,
                _ if end2.is_some() && open_sp.is_none() => {
                    return Err(err(
                        line,
                        "after END2 only subroutines (SP … SPE) may follow".into(),
                    ))
                }
                Instr::Lbl(n) if self.labels.contains_key(&(scope, n)) => {
                    return Err(err(line, format!("label L{n} twice in one level")));
                }
                Instr::Lbl(n) => {
                    self.labels.insert((scope, n), i);
                }
                _ => {}
            }
            self.scope.push(scope);
        }
        if let Some((n, line)) = open_sp {
            return Err(err(line, format!("subroutine P{n} has no SPE")));
        }
        self.end1 = end1.ok_or_else(|| err(last_line, "no END1".into()))?;
        self.end2 = end2.ok_or_else(|| err(last_line, "no END2".into()))?;
        for (i, s) in self.steps.iter().enumerate() {
            match s.instr {
                Instr::Jmpb(n) if !self.labels.contains_key(&(self.scope[i], n)) => {
                    return Err(err(
                        s.line,
                        format!("JMPB L{n}: no such label in this level"),
                    ))
                }
                Instr::Call(n) | Instr::Callu(n) if !self.subroutines.contains_key(&n) => {
                    return Err(err(s.line, format!("CALL P{n}: no such subroutine")))
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Follows the stack depth along each rung: no instruction may need more entries than the
    /// rung pushed (ACT must exist), and no rung may push more than ST0–ST7.
    pub(super) fn check_stack(&self) -> Result<(), LoadError> {
        let mut depth = 0usize;
        for s in &self.steps {
            let err = |reason: String| LoadError {
                line: s.line,
                reason,
            };
            match &s.instr {
                Instr::Rd(_) | Instr::RdNot(_) => depth = 1,
                Instr::RdStk(_) | Instr::RdNotStk(_) => {
                    if depth == 0 {
                        return Err(err("RD.STK without a rung to push (start with RD)".into()));
                    }
                    depth += 1;
                    if depth > STACK_DEPTH {
                        return Err(err(format!(
                            "logic stack deeper than ST0–ST{}",
                            STACK_DEPTH - 1
                        )));
                    }
                }
                Instr::AndStk | Instr::OrStk => {
                    if depth < 2 {
                        return Err(err(format!("{} needs two stack entries", s.text)));
                    }
                    depth -= 1;
                }
                i if i.inputs() == 0 => depth = 0,
                i => {
                    if depth == 0 {
                        return Err(err(format!(
                            "{}: no logic before it (start the rung with RD)",
                            s.text
                        )));
                    }
                    // Inputs below ACT are taken if the rung pushed them; the output is in ST0.
                    depth -= depth.min(i.inputs()) - 1;
                }
            }
        }
        Ok(())
    }

    /// Subroutine calls must not recurse.
    pub(super) fn check_calls(&self) -> Result<(), LoadError> {
        // Calls made by each subroutine (by P number) and from the levels.
        let mut calls: HashMap<u16, Vec<(u16, u32)>> = HashMap::new();
        let owner: HashMap<usize, u16> = self
            .subroutines
            .iter()
            .map(|(p, first)| (*first, *p))
            .collect();
        for (i, s) in self.steps.iter().enumerate() {
            if let (Instr::Call(n) | Instr::Callu(n), Some(p)) =
                (&s.instr, owner.get(&self.scope[i]))
            {
                calls.entry(*p).or_default().push((*n, s.line));
            }
        }
        fn visit(
            p: u16,
            calls: &HashMap<u16, Vec<(u16, u32)>>,
            path: &mut Vec<u16>,
            done: &mut HashSet<u16>,
        ) -> Result<(), LoadError> {
            if done.contains(&p) {
                return Ok(());
            }
            path.push(p);
            for (q, line) in calls.get(&p).into_iter().flatten() {
                if path.contains(q) {
                    return Err(LoadError {
                        line: *line,
                        reason: format!("subroutine P{q} calls itself (through P{p})"),
                    });
                }
                if path.len() >= MAX_CALL_DEPTH {
                    return Err(LoadError {
                        line: *line,
                        reason: format!("subroutines nested deeper than {MAX_CALL_DEPTH}"),
                    });
                }
                visit(*q, calls, path, done)?;
            }
            path.pop();
            done.insert(p);
            Ok(())
        }
        let mut done = HashSet::new();
        let mut keys: Vec<u16> = self.subroutines.keys().copied().collect();
        keys.sort_unstable();
        for p in keys {
            visit(p, &calls, &mut Vec::new(), &mut done)?;
        }
        Ok(())
    }
}
