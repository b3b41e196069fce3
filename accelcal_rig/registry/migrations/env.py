"""Alembic's entry point: the registry hands it the connection to migrate (accelcal_rig/registry/database.py)."""

from alembic import context

connection = context.config.attributes["connection"]
context.configure(connection=connection, render_as_batch=connection.dialect.name == "sqlite")
with context.begin_transaction():
    context.run_migrations()
