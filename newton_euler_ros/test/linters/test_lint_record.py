# Copyright 2026 newton_euler_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""The lint record: a pass holds for the same bytes only."""
import os

from lint_record import not_passed, python_files, record_passed, \
    record_path


def test_a_changed_file_is_linted_again(tmp_path, monkeypatch):
    monkeypatch.delenv('NEWTON_EULER_RECHECK', raising=False)
    (tmp_path / 'pkg' / '_hidden').mkdir(parents=True)
    (tmp_path / 'pkg' / '.dot').mkdir()
    a, b = tmp_path / 'pkg' / 'a.py', tmp_path / 'pkg' / 'b.py'
    a.write_text('x = 1\n')
    b.write_text('y = 2\n')
    (tmp_path / 'pkg' / '_hidden' / 'c.py').write_text('z = 3\n')
    (tmp_path / 'pkg' / '.dot' / 'd.py').write_text('z = 4\n')
    (tmp_path / 'pkg' / 'notes.txt').write_text('not python\n')
    files = python_files([str(tmp_path / 'pkg')])
    assert files == [str(a), str(b)]
    record = str(tmp_path / 'cache' / 'record')
    assert not_passed(record, files) == files      # no record yet
    record_passed(record, files)
    assert not_passed(record, files) == []
    a.write_text('x = 1  \n')                       # one byte more
    assert not_passed(record, files) == [str(a)]
    monkeypatch.setenv('NEWTON_EULER_RECHECK', '1')
    assert not_passed(record, files) == files
    # a cache that cannot be written: no record, no error
    (tmp_path / 'a_file').write_text('')
    nowhere = str(tmp_path / 'a_file' / 'record')
    record_passed(nowhere, files)
    monkeypatch.delenv('NEWTON_EULER_RECHECK')
    assert not_passed(nowhere, files) == files


def test_the_record_is_per_linter_and_options(monkeypatch, tmp_path):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))

    def one():
        return 1

    def other():
        return 2
    assert record_path('flake8', one) == record_path('flake8', one)
    assert record_path('flake8', one) != record_path('flake8', other)
    assert record_path('flake8', one) != record_path('pep257', one)
    assert record_path('flake8', one).startswith(str(tmp_path) + os.sep)


def test_the_package_is_found_as_the_linters_find_it():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    files = python_files([os.path.dirname(here)])
    assert os.path.abspath(__file__) in files
    assert not any('__pycache__' in f for f in files)
    assert len(files) > 50
