"""A run's report: its numbers (`results`, `interface_loads`, `cost`, and `headline`, the
headline numbers as a Markdown table), the out directory (`out_dir`), the figures
(`run_figures`, `ledger_figures`, `initial_figure`, `figure_kit`) and the replay (`replay`,
`replay_marks`). Imports the `scenario`, `geometry` and `model` wings."""
