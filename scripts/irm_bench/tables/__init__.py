"""One module per table (or per group of tables that share their maps); registry.TABLES lists
them in print order. Each has TITLE, MODES, requests(ctx) and tables(ctx, results)."""
