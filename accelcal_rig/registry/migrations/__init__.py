"""Alembic migrations of the registry's schema: each version a file in versions/, applied in order at open."""
