//! `raytree lessons` and `raytree lesson check|answer|show`: the lessons from the command
//! line, for teachers who write them and courses that grade with them (docs/lessons.md).
//!
//! Exit codes: `check` 0 when every lesson is good, 1 with one sentence per problem; `answer`
//! 0 right, 1 wrong (with the hint), 2 when the answer cannot be evaluated (no such lesson or
//! step, an answer of the wrong kind); usage errors are 2 as everywhere.

use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Subcommand};
use raytree::lessons::{self, Answer, Lesson, TaskKind, choice_options};
use raytree::trace::TraceSettings;

use super::parse_pixel;

#[derive(Args, Debug)]
pub struct LessonArgs {
    #[command(subcommand)]
    command: LessonCommand,
}

#[derive(Subcommand, Debug)]
enum LessonCommand {
    /// Validate lessons: the scene loads, every task can be evaluated and has a correct answer
    /// on its scene (named: a pixel that passes, a control value, the number, the option).
    Check {
        /// Lesson files or names of shipped lessons.
        #[arg(required = true, value_name = "FILE_OR_NAME")]
        lessons: Vec<String>,
    },
    /// Evaluate one answer to a step's task: exit 0 when right, 1 when wrong (with the hint).
    Answer(AnswerArgs),
    /// Print a lesson: its introduction, and each step with its task and options.
    Show {
        #[arg(value_name = "FILE_OR_NAME")]
        lesson: String,
    },
}

#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("answer").required(true).args(["pixel", "value", "choice"])))]
pub struct AnswerArgs {
    /// Lesson file or name of a shipped lesson.
    #[arg(value_name = "FILE_OR_NAME")]
    lesson: String,
    /// The step, counted from 1.
    step: usize,
    /// A pixel task's answer, as X,Y.
    #[arg(long, value_parser = parse_pixel)]
    pixel: Option<(u32, u32)>,
    /// A value task's number, or a control task's new value.
    #[arg(long, allow_hyphen_values = true)]
    value: Option<f64>,
    /// A choice task's option (its key or letter), or a named control's value.
    #[arg(long)]
    choice: Option<String>,
}

/// `raytree lessons`: one line per shipped lesson.
pub fn run_lessons() -> Result<()> {
    for lesson in Lesson::all_shipped() {
        let lesson = lesson?;
        out!("{:<27} {} — {}", lesson.name, lesson.title, lesson.summary);
    }
    Ok(())
}

pub fn run_lesson(args: &LessonArgs) -> ExitCode {
    match &args.command {
        LessonCommand::Check { lessons } => run_check(lessons),
        LessonCommand::Answer(a) => match run_answer(a) {
            Ok(true) => ExitCode::SUCCESS,
            Ok(false) => ExitCode::from(1),
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        LessonCommand::Show { lesson } => match run_show(lesson) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

fn run_check(args: &[String]) -> ExitCode {
    let mut problems = 0;
    for arg in args {
        let lesson = match Lesson::open(arg) {
            Ok(l) => l,
            Err(e) => {
                eprintln!("error: {e}");
                problems += 1;
                continue;
            }
        };
        let report = lessons::check_lesson(&lesson);
        for a in &report.answers {
            out!("{}: {a}", lesson.name);
        }
        for p in &report.problems {
            eprintln!("error: {p}");
        }
        problems += report.problems.len();
        if report.problems.is_empty() {
            let tasks = lesson.steps.iter().filter(|s| s.task.is_some()).count();
            out!(
                "{}: good ({} steps, {tasks} tasks, each with an answer that passes)",
                lesson.name,
                lesson.steps.len()
            );
        }
    }
    if problems == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn run_answer(a: &AnswerArgs) -> Result<bool> {
    let lesson = Lesson::open(&a.lesson)?;
    let Some(step) = lesson.step(a.step) else {
        anyhow::bail!(
            "{} has steps 1 to {}, not {}",
            lesson.name,
            lesson.steps.len(),
            a.step
        );
    };
    let answer = match (a.pixel, a.value, &a.choice) {
        (Some((x, y)), _, _) => Answer::Pixel([x, y]),
        (_, Some(v), _) => Answer::Value(v),
        (_, _, Some(k)) => Answer::Choice(k.clone()),
        _ => anyhow::bail!("give one answer: --pixel X,Y, --value V or --choice K"),
    };
    let scene = lesson.load_scene()?;
    let verdict = lessons::evaluate(step, &answer, &scene, &TraceSettings::default())?;
    out!("{}", verdict.message);
    if !verdict.correct {
        if let Some(hint) = &verdict.hint {
            out!(
                "hint: {}",
                hint.split_whitespace().collect::<Vec<_>>().join(" ")
            );
        }
        if let (Some(node), Some([x, y])) = (&verdict.node, verdict.pixel) {
            out!("see: node {node} of the tree of pixel ({x}, {y})");
        }
    }
    Ok(verdict.correct)
}

fn run_show(arg: &str) -> Result<()> {
    let lesson = Lesson::open(arg)?;
    let flat = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    out!("{}\n\n{}\n", lesson.title, flat(&lesson.intro));
    for step in &lesson.steps {
        out!("{}. {}", step.number, flat(&step.text));
        if let Some(task) = &step.task {
            if let Some(p) = &task.prompt {
                out!("   task ({}): {}", task.kind.name(), flat(p));
            } else {
                out!("   task ({})", task.kind.name());
            }
            if let TaskKind::Choice { question, .. } = &task.kind {
                for (i, o) in choice_options(question).iter().enumerate() {
                    out!("     {}) {} [{}]", (b'a' + i as u8) as char, o.label, o.key);
                }
            }
        }
    }
    Ok(())
}
